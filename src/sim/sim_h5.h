/* private: the collection file (LIBERO / robomimic HDF5 layout, keys in
 * docs/simulation.md) as written by collection and merging (sim_h5.c).
 * Both go through the same calls in the same order, so a merge of shards
 * gives the bytes of one run. */
#ifndef HEARTH_SIM_H5_H
#define HEARTH_SIM_H5_H

#include <hdf5.h>
#include <stddef.h>
#include <stdint.h>

#include "hearth/core.h"
#include "hearth/sim.h"

/* one demonstration in memory: per sample, rows of the widths below */
#define SIM_ROBOT_STATE_DIM 9 /* gripper qpos (2), ee pos (3), ee quat x y z w (4) */
typedef struct sim_demo {
  size_t T, cap;                    /* samples stored, samples allocated */
  size_t nstate, img;               /* state length; bytes per image (S * S * 3) */
  double *actions;                  /* T x 7 */
  double *states;                   /* T x nstate: [time, qpos, qvel] */
  double *joint;                    /* T x 7 */
  double *grip;                     /* T x 2 */
  double *ee;                       /* T x 6: ee pos, ee axis-angle */
  double *robot;                    /* T x SIM_ROBOT_STATE_DIM */
  uint8_t *front, *thermal, *wrist; /* T x img each */
  uint64_t layout;
  int instruction; /* 0 or 1: index into the task's instructions */
  /* dynamic temperatures (nth 0: none): region temperatures per sample,
   * T x nth, and what the columns are (owned, malloc'd) */
  size_t nth;
  float *th;
  char *th_names; /* "obj<k>/<category>/<state>/<region>" per column, ';'-separated */
  double *th_C;   /* nth heat capacities, J/K */
} sim_demo;
/* Make room for cap samples (keeps what is stored); 0 when out of memory. */
int sim_demo_grow(sim_demo *b, size_t cap);
/* Free the buffers and zero b (sizes included). */
void sim_demo_free(sim_demo *b);

/* String attributes of group data, in the order they are written (after
 * the demos). */
typedef enum sim_h5_key {
  SIM_H5_ENV_NAME,
  SIM_H5_PROBLEM_INFO,
  SIM_H5_ENV_ARGS,
  SIM_H5_BDDL_FILE_NAME,
  SIM_H5_BDDL_FILE_CONTENT,
  SIM_H5_MACROS_IMAGE_CONVENTION,
  SIM_H5_INSTRUCTIONS,
  SIM_H5_IMAGE_ROW_ORDER,
  SIM_H5_THERMAL_COLORMAP,
  SIM_H5_NKEYS
} sim_h5_key;
/* the attribute name of each key */
extern const char *const sim_h5_key_names[SIM_H5_NKEYS];

/* What a file says about itself: the string attributes of data (owned,
 * malloc'd; sim_h5_meta_free releases them). */
typedef struct sim_h5_meta {
  char *str[SIM_H5_NKEYS];
} sim_h5_meta;
void sim_h5_meta_free(sim_h5_meta *m);

/* The file-level attributes of a collection with options o whose files hold
 * instructions ins_first .. ins_first + ins_count - 1 (problem_info and the
 * BDDL text name ins_first), rendered with the GL back end gl ("osmesa" or
 * "egl"). m's strings are the caller's to free (sim_h5_meta_free). */
hearth_status sim_h5_describe(const hearth_sim_collect_opts *o, int ins_first, int ins_count,
                              const char *gl, sim_h5_meta *m, hearth_err *err);

/* A shard's place (written only in the files of a sharded collection):
 * data@hearth_shard "I/N" and data@hearth_layouts L. */
typedef struct sim_h5_shard {
  int index, count;
  long long layouts;
} sim_h5_shard;

/* ---- writing ---------------------------------------------------------------- */
/* the deflate level of the image chunks (libdeflate's scale, see sim_h5.c) */
#define SIM_H5_DEFLATE_LEVEL 1
struct libdeflate_compressor;
typedef struct sim_h5_out {
  hearth_atomic_file af; /* the temporary name HDF5 writes to, renamed on finish */
  hid_t f, data;
  int ndemo;
  long long total;                  /* samples over the demos */
  struct libdeflate_compressor *zc; /* the image chunks' compressor, made on first use */
  uint8_t *zbuf;                    /* zcap bytes: one compressed frame */
  size_t zcap;
} sim_h5_out;
/* Create path's temporary file and its group data. */
hearth_status sim_h5_create(sim_h5_out *o, const char *path, hearth_err *err);
/* Append data/demo_<ndemo>: its attributes (num_samples, layout,
 * instruction_index, language_instruction, model_file, init_state), its
 * datasets and obs/ group. Images are S x S. */
hearth_status sim_h5_add_demo(sim_h5_out *o, const sim_demo *b, int S, const char *instruction,
                              const char *model_file, hearth_err *err);
/* Write data's attributes (meta, num_demos, total and, if shard is not
 * NULL, the shard's), close and rename into place. On failure nothing is
 * left behind. Closes o either way. */
hearth_status sim_h5_finish(sim_h5_out *o, const sim_h5_meta *m, const sim_h5_shard *shard,
                            hearth_err *err);
/* Close and remove the temporary file (o may be zeroed). */
void sim_h5_abort(sim_h5_out *o);

/* ---- reading (merge) ----------------------------------------------------------- */
typedef struct sim_h5_in {
  char path[4096];
  hid_t f, data;
  int ndemo;
  sim_h5_shard shard; /* count 0: the file is not a shard */
  sim_h5_meta meta;
} sim_h5_in;
/* Open a collection file: its meta, num_demos and shard attributes. */
hearth_status sim_h5_open(sim_h5_in *in, const char *path, hearth_err *err);
/* Read data/demo_<idx> into b (grown as needed; b->nstate and b->img are
 * taken from the file), with its instruction text and model file
 * (malloc'd, the caller frees them); *S is its image side. */
hearth_status sim_h5_read_demo(sim_h5_in *in, int idx, sim_demo *b, int *S, char **instruction,
                               char **model_file, hearth_err *err);
void sim_h5_close(sim_h5_in *in);

#endif
