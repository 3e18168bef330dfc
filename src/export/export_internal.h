/* Private to the export area: the HDF5 collection reader
 * (export_hdf5.c), LeRobot's episode statistics as numpy computes them and
 * Python-style JSON text (export_stats.c), used by export_lerobot.c. */
#ifndef HEARTH_EXPORT_INTERNAL_H
#define HEARTH_EXPORT_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"

/* ---- a collection file ------------------------------------------------------- */
typedef struct ex_source {
  char path[4096];
  char task[8];          /* "H1".."H3", from data@env_args env_name "hearth_<task>" */
  int64_t seed;          /* env_kwargs.seed */
  int fps;               /* env_kwargs.control_freq */
  int size;              /* env_kwargs.camera_heights (= camera_widths) */
  char asset_source[64]; /* env_kwargs.asset_source, "" if absent */
  char renderer[64];     /* env_kwargs.renderer, "" if absent */
  int64_t num_demos;
  /* a dynamic-temperature collection's obs/thermal_state (docs/simulation.md):
   * its columns in demo_0 and their region_names (`;`-separated); 0 and ""
   * when the file has none. Every demo must have the same. */
  int th_dim;
  char th_names[4096];
  int64_t file_id; /* the open HDF5 file (hid_t) */
} ex_source;

/* Open path and read data's attributes; checks image_row_order. */
hearth_status ex_source_open(const char *path, ex_source *s, hearth_err *err);
void ex_source_close(ex_source *s);

typedef struct ex_demo {
  size_t T;
  int64_t layout, instruction_index;
  char instruction[1024];
  double *actions, *ee_pos, *ee_ori, *gripper; /* T x 7, 3, 3, 2 */
  uint8_t *rgb, *wrist, *thermal;              /* T x size x size x 3, OpenGL rows */
  float *thermal_state;                        /* T x th_dim, degC, or NULL */
} ex_demo;

/* Read data/demo_<k> (agentview_thermal and thermal_state only if
 * want_thermal); d is zeroed first and freed with ex_demo_free (also after
 * a failure). */
hearth_status ex_demo_read(const ex_source *s, int64_t k, int want_thermal, ex_demo *d,
                           hearth_err *err);
void ex_demo_free(ex_demo *d);

/* ---- text -------------------------------------------------------------------- */
typedef struct ex_text {
  char *p;
  size_t n, cap;
  int failed;
} ex_text;
void ex_puts(ex_text *t, const char *s);
void ex_printf(ex_text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void ex_text_free(ex_text *t);
/* x as Python's repr(float) writes it (the shortest text that reads back
 * as x: "0.1", "3.0", "1e-05", "1.5e+16"; NaN and Infinity as json.dumps) */
void ex_put_float(ex_text *t, double x);
/* a JSON string, escaped as Python's json.dumps(ensure_ascii=False) */
void ex_put_jstr(ex_text *t, const char *s);

/* ---- numpy's reductions ---------------------------------------------------- */
/* np.add.reduce over n contiguous float64: inner loops of at most 8192
 * elements (numpy's buffer), each summed pairwise, added in order. */
double ex_np_sum(const double *x, size_t n);
/* the same, added chunk by chunk to acc (a reduction that goes on over
 * several planes into one output) */
double ex_np_sum_into(double acc, const double *x, size_t n);

/* One feature's stats as lerobot's compute_episode_stats leaves them. */
#define EX_STATS_MAX_DIM 64
typedef struct ex_stats {
  int dim;     /* values per frame (image features: 3 channels) */
  int integer; /* min and max are integers (int64 features) */
  int image;   /* shape (3, 1, 1) */
  double min[EX_STATS_MAX_DIM], max[EX_STATS_MAX_DIM], mean[EX_STATS_MAX_DIM],
      std[EX_STATS_MAX_DIM];
  int64_t count;
} ex_stats;

/* float32 (T, dim), reduced over axis 0 in float32 (dim <= EX_STATS_MAX_DIM). */
void ex_stats_f32(const float *x, size_t T, int dim, ex_stats *s);
/* float64 (T,), e.g. timestamps (frame_index / fps in Python floats). */
hearth_status ex_stats_f64(const double *x, size_t T, ex_stats *s, hearth_err *err);
/* int64 (T,). */
hearth_status ex_stats_i64(const int64_t *x, size_t T, ex_stats *s, hearth_err *err);
/* Image frames (T x h x w x 3 U8, as stored): the frames of
 * sample_indices(T), downsampled as auto_downsample_height_width, per
 * channel, divided by 255; count = frames sampled. */
hearth_status ex_stats_images(const uint8_t *frames, size_t T, int w, int h, ex_stats *s,
                              hearth_err *err);
/* "name": {"min": ..., "max": ..., "mean": ..., "std": ..., "count": [n]} */
void ex_put_stats(ex_text *t, const char *name, const ex_stats *s);

#endif
