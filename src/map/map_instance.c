/* hearth map --rgb on one instance as one transaction: the colour bake and
 * the temperature maps of its states are written into temporaries and put
 * in place together (see hearth_map_bake_run in include/hearth/map.h). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>
#include "hearth/map.h"

#define PATH_SZ 4096

/* the outputs of one run: final paths and their temporaries ("" when not
 * made yet); owned by hearth_map_bake_run's frame */
typedef struct bake_outputs {
  char texture[PATH_SZ], mesh[PATH_SZ];
  char texture_tmp[PATH_SZ], mesh_tmp[PATH_SZ];
  size_t n;
  char (*dir)[PATH_SZ];     /* n final state directories */
  char (*dir_tmp)[PATH_SZ]; /* their temporaries */
} bake_outputs;

static hearth_status outputs_plan(const hearth_map_job *map, const char *const *states, size_t n,
                                  bake_outputs *o, hearth_err *err) {
  const char *root = map->root, *inst = map->instance;
  char derived[PATH_SZ];
  int w = snprintf(derived, sizeof derived, "%s/instances/%s/derived", root, inst);
  if (w < 0 || (size_t)w + 32 >= sizeof derived)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s/instances/%s: path too long", root, inst);
  snprintf(o->texture, PATH_SZ, "%s/rgb_texture.png", derived);
  snprintf(o->mesh, PATH_SZ, "%s/mesh.glb", derived);
  o->dir = calloc(n ? n : 1, sizeof *o->dir);
  o->dir_tmp = calloc(n ? n : 1, sizeof *o->dir_tmp);
  if (!o->dir || !o->dir_tmp) return hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
  o->n = n;
  for (size_t k = 0; k < n; k++) {
    w = snprintf(o->dir[k], PATH_SZ, "%s/%s", derived, states[k]);
    if (w < 0 || (size_t)w >= PATH_SZ)
      return hearth_err_set(err, HEARTH_E_LIMIT, "%s/%s: path too long", derived, states[k]);
  }
  hearth_status s = hearth_mkdirs(derived, err);
  /* what killed earlier runs left beside these outputs */
  if (!s) s = hearth_sweep_temps_of(o->texture, NULL, err);
  if (!s) s = hearth_sweep_temps_of(o->mesh, NULL, err);
  for (size_t k = 0; k < n && !s; k++) s = hearth_sweep_temps_of(o->dir[k], NULL, err);
  return s;
}

static void outputs_discard(bake_outputs *o) {
  if (o->texture_tmp[0]) unlink(o->texture_tmp);
  if (o->mesh_tmp[0]) unlink(o->mesh_tmp);
  for (size_t k = 0; k < o->n; k++)
    if (o->dir_tmp[k][0]) hearth_remove_tree(o->dir_tmp[k], NULL);
  free(o->dir);
  free(o->dir_tmp);
  memset(o, 0, sizeof *o);
}

/* every step succeeded: the temporaries take the final names */
static hearth_status outputs_commit(bake_outputs *o, hearth_err *err) {
  if (rename(o->texture_tmp, o->texture) != 0)
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot rename into place: %s", o->texture,
                          strerror(errno));
  o->texture_tmp[0] = 0;
  if (rename(o->mesh_tmp, o->mesh) != 0)
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot rename into place: %s", o->mesh,
                          strerror(errno));
  o->mesh_tmp[0] = 0;
  for (size_t k = 0; k < o->n; k++) {
    hearth_status s = hearth_replace_dir(o->dir_tmp[k], o->dir[k], err);
    if (s) return s;
    o->dir_tmp[k][0] = 0;
  }
  return HEARTH_OK;
}

hearth_status hearth_map_bake_run(const hearth_map_job *map, const hearth_bake_job *bake,
                                  const char *const *states, size_t n_states,
                                  hearth_map_result *stats, double *seconds, size_t *bake_peak_kib,
                                  hearth_err *err) {
  if (!map || !bake || !map->root || !map->instance || (n_states && !states))
    return hearth_err_set(err, HEARTH_E_ARG, "map: root, instance and states are required");
  bake_outputs o;
  memset(&o, 0, sizeof o);
  hearth_status s = outputs_plan(map, states, n_states, &o, err);
  /* the bake first: it reads another state's colour views, so a bad one
   * stops the run before any map is made */
  if (!s) s = hearth_temp_file(o.texture, o.texture_tmp, PATH_SZ, NULL, err);
  if (!s) s = hearth_temp_file(o.mesh, o.mesh_tmp, PATH_SZ, NULL, err);
  if (!s) {
    hearth_bake_job bj = *bake;
    bj.root = map->root;
    bj.instance = map->instance;
    bj.out_texture = o.texture_tmp;
    bj.out_mesh = o.mesh_tmp;
    double t0 = hearth_now();
    s = hearth_bake_rgb_run(&bj, err);
    if (seconds) seconds[0] = hearth_now() - t0;
    struct rusage ru;
    if (bake_peak_kib) *bake_peak_kib = getrusage(RUSAGE_SELF, &ru) ? 0 : (size_t)ru.ru_maxrss;
  }
  for (size_t k = 0; k < n_states && !s; k++) {
    if ((s = hearth_temp_dir(o.dir[k], o.dir_tmp[k], PATH_SZ, err))) break;
    hearth_map_job mj = *map;
    mj.state = states[k];
    mj.out_dir = o.dir_tmp[k];
    double t0 = hearth_now();
    s = hearth_map_run(&mj, stats ? &stats[k] : NULL, err);
    if (seconds) seconds[k + 1] = hearth_now() - t0;
  }
  if (!s) s = outputs_commit(&o, err);
  outputs_discard(&o);
  return s;
}
