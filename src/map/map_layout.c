/* The mapping layout (see map_internal.h): the UV raster and islands, the
 * triangles' normals, the mesh's bounding sphere, and the camera's pixel
 * grid with its ray fan. The pixel grid and the islands are made on
 * threads of their own while the UV layout is rasterised; the layout owns
 * every array it holds (not the mesh). */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include "map/map_internal.h"

/* the pixel grid (undistorted centres of every stride-th pixel) and its ray
 * fan, then the UV islands, each made on a thread of its own (all only
 * read their inputs) */
typedef struct grid_build {
  const hearth_camera *cam;
  size_t stride, pw, ph;
  const float *pix_dir; /* the fan's directions, or made here without a fan */
  int own_pix_dir;      /* pix_dir is not the fan's */
  hearth_ray_fan *fan;  /* NULL where the fan cannot hold the grid */
  int nomem;
  /* then the UV islands (the mesh only) */
  const hearth_mesh *mesh;
  uint32_t *island_of_tri, n_islands;
  hearth_status islands_status;
  hearth_err islands_err;
} grid_build;

static void *grid_build_run(void *arg) {
  grid_build *g = arg;
  size_t st = g->stride, pw = g->pw, ph = g->ph, np = pw * ph;
  hearth_status s = hearth_ray_fan_new(g->cam, st, &g->fan, NULL);
  if (s == HEARTH_OK) {
    /* the fan's directions are the grid's (zero where never cast) */
    g->pix_dir = hearth_ray_fan_dirs(g->fan, NULL, NULL);
    return NULL;
  }
  g->nomem = s == HEARTH_E_NOMEM;
  float *dir = hearth_alloc_array(np, 3 * sizeof *dir);
  if (!dir) {
    g->nomem = 1;
    return NULL;
  }
  g->pix_dir = dir;
  g->own_pix_dir = 1;
  /* a pixel the lens model cannot invert gets a zero direction: never cast */
  if (hearth_camera_ray_grid(g->cam, st, dir))
    for (size_t k = 0; k < 3 * np; k++)
      if (isnan(dir[k])) dir[k] = 0.0f;
  return NULL;
}

static void *islands_run(void *arg) {
  grid_build *g = arg;
  g->islands_status = hearth_uv_islands(g->mesh, g->island_of_tri, &g->n_islands, &g->islands_err);
  return NULL;
}

/* the rasterised triangle of each texel of rows [b, e) replaced by its
   island, in place */
static void texel_islands(void *ctx, size_t b, size_t e, int t) {
  hearth_map_layout *l = ctx;
  (void)t;
  for (size_t q = b * l->R; q < e * l->R; q++) {
    uint32_t tq = l->island_of_texel[q];
    l->island_of_texel[q] = tq == UINT32_MAX ? UINT32_MAX : l->island_of_tri[tq];
  }
}

/* unit normals of triangles [b, e) (0 for a degenerate one) */
static void tri_normals(void *ctx, size_t b, size_t e, int t) {
  hearth_map_layout *l = ctx;
  const hearth_mesh *mesh = l->mesh;
  (void)t;
  for (size_t i = b; i < e; i++) {
    const uint32_t *ix = mesh->indices + 3 * i;
    const float *a = mesh->positions + 3 * ix[0], *bb = mesh->positions + 3 * ix[1],
                *c = mesh->positions + 3 * ix[2];
    double e1[3] = {bb[0] - a[0], bb[1] - a[1], bb[2] - a[2]},
           e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double nn[3];
    hearth_cross3(e1, e2, nn);
    double len = hearth_norm3(nn);
    for (int k = 0; k < 3; k++) l->tri_normal[3 * i + k] = len > 0 ? (float)(nn[k] / len) : 0.0f;
  }
}

/* ---- smoothed normals for the viewing cosines ---------------------------------- */
/* l->cos_normal: each triangle's normal averaged `passes` times over the
   triangles sharing a vertex position with it (area-weighted, neighbours
   whose face normal is more than 60 degrees off its own left out) */
static hearth_status smooth_normals(hearth_map_layout *l, int passes, hearth_err *err) {
  const hearth_mesh *m = l->mesh;
  const size_t nv = m->n_vertices, nt = m->n_triangles;
  uint32_t *canon = hearth_alloc_array(nv ? nv : 1, sizeof *canon);
  size_t *start = calloc(nv + 1, sizeof *start);
  size_t *fill = hearth_alloc_array(nv ? nv : 1, sizeof *fill);
  uint32_t *vt = hearth_alloc_array(nt ? 3 * nt : 1, sizeof *vt);
  float *area = hearth_alloc_array(nt ? nt : 1, sizeof *area);
  float *a = hearth_alloc_array(nt ? 3 * nt : 1, sizeof *a);
  float *b = hearth_alloc_array(nt ? 3 * nt : 1, sizeof *b);
  hearth_status s = HEARTH_OK;
  if (!canon || !start || !fill || !vt || !area || !a || !b) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory for the smoothed normals");
    free(a);
    goto done;
  }
  /* vertices welded by position (a UV seam splits a vertex) */
  if ((s = hearth_mesh_weld_ids(m, canon, err))) {
    free(a);
    goto done;
  }
  for (size_t t = 0; t < nt; t++)
    for (int c = 0; c < 3; c++) start[canon[m->indices[3 * t + c]] + 1]++;
  for (size_t v = 0; v < nv; v++) start[v + 1] += start[v];
  memcpy(fill, start, nv * sizeof *fill);
  for (size_t t = 0; t < nt; t++)
    for (int c = 0; c < 3; c++) vt[fill[canon[m->indices[3 * t + c]]]++] = (uint32_t)t;
  for (size_t t = 0; t < nt; t++) {
    const uint32_t *ix = m->indices + 3 * t;
    const float *p0 = m->positions + 3 * ix[0], *p1 = m->positions + 3 * ix[1],
                *p2 = m->positions + 3 * ix[2];
    double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]},
           e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]}, nn[3];
    hearth_cross3(e1, e2, nn);
    area[t] = (float)hearth_norm3(nn);
  }
  memcpy(a, l->tri_normal, 3 * nt * sizeof *a);
  for (int pass = 0; pass < passes; pass++) {
    for (size_t t = 0; t < nt; t++) {
      const float *n0 = l->tri_normal + 3 * t;
      double sum[3] = {0, 0, 0};
      /* a neighbour sharing two vertices counts twice, its own triangle three times */
      for (int c = 0; c < 3; c++) {
        const uint32_t v = canon[m->indices[3 * t + c]];
        for (size_t k = start[v]; k < start[v + 1]; k++) {
          const uint32_t u = vt[k];
          const float *nu = l->tri_normal + 3 * u;
          if (n0[0] * nu[0] + n0[1] * nu[1] + n0[2] * nu[2] < 0.5f) continue;
          for (int q = 0; q < 3; q++) sum[q] += (double)area[u] * a[3 * u + q];
        }
      }
      double ln = hearth_norm3(sum);
      for (int q = 0; q < 3; q++) b[3 * t + q] = ln > 0 ? (float)(sum[q] / ln) : n0[q];
    }
    float *tmp = a;
    a = b;
    b = tmp;
  }
  l->cos_normal = a;
done:
  free(canon);
  free(start);
  free(fill);
  free(vt);
  free(area);
  free(b);
  return s;
}

/* the box centre and the farthest vertex from it, padded so that rounding
   can never cull a ray that touches the mesh */
static void bounding_sphere(const hearth_mesh *mesh, double sphere[4]) {
  double lo[3], hi[3], r2 = 0;
  hearth_mesh_bounds(mesh, lo, hi);
  for (int k = 0; k < 3; k++) sphere[k] = 0.5 * (lo[k] + hi[k]);
  for (size_t i = 0; i < mesh->n_vertices; i++) {
    const float *pv = mesh->positions + 3 * i;
    double dx = pv[0] - sphere[0], dy = pv[1] - sphere[1], dz = pv[2] - sphere[2];
    double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 > r2) r2 = d2;
  }
  sphere[3] = sqrt(r2) * (1.0 + 1e-3) + 1e-6;
}

/* the pixel grid's size and arrays, and the triangles' islands */
static hearth_status alloc_grid(hearth_map_layout *l, hearth_err *err) {
  const size_t st = l->stride;
  l->pw = ((size_t)l->cam.width + st - 1) / st;
  l->ph = ((size_t)l->cam.height + st - 1) / st;
  l->np = l->pw * l->ph;
  if (l->np > UINT32_MAX / 4)
    return hearth_err_set(err, HEARTH_E_LIMIT, "map: a %zu x %zu pixel grid exceeds the limit",
                          l->pw, l->ph);
  const size_t nt = l->mesh->n_triangles;
  l->island_of_tri = hearth_alloc_array(nt ? nt : 1, sizeof *l->island_of_tri);
  if (!l->island_of_tri) return hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
  return HEARTH_OK;
}

/* everything of l after its inputs: the pixel grid and the islands on
   threads of their own beside the UV raster, then each texel's island, the
   normals and the bounding sphere */
static hearth_status build_layout(hearth_map_layout *l, hearth_err *err) {
  const hearth_mesh *mesh = l->mesh;
  const size_t R = l->R;
  grid_build gb = {0};
  pthread_t gb_tid, isl_tid;
  int gb_started = 0, isl_started = 0;
  hearth_status s = alloc_grid(l, err);
  if (s) goto done;
  gb = (grid_build){.cam = &l->cam,
                    .stride = l->stride,
                    .pw = l->pw,
                    .ph = l->ph,
                    .mesh = mesh,
                    .island_of_tri = l->island_of_tri};
  gb_started = pthread_create(&gb_tid, NULL, grid_build_run, &gb) == 0;
  if (!gb_started) grid_build_run(&gb); /* no thread: make it here */
  isl_started = pthread_create(&isl_tid, NULL, islands_run, &gb) == 0;
  if (!isl_started) islands_run(&gb);
  l->tri_normal = hearth_alloc_array(mesh->n_triangles, 3 * sizeof *l->tri_normal);
  l->island_of_texel = hearth_alloc_array(R * R, sizeof *l->island_of_texel);
  if (!l->tri_normal || !l->island_of_texel) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory for R=%zu", R);
    goto done;
  }
  /* each texel's triangle, made its island below */
  if ((s = hearth_uv_rasterize(mesh, R, l->island_of_texel, NULL, err))) goto done;
  if (gb_started) pthread_join(gb_tid, NULL);
  if (isl_started) pthread_join(isl_tid, NULL);
  gb_started = isl_started = 0;
  if (gb.islands_status) {
    if (err) *err = gb.islands_err;
    s = gb.islands_status;
    goto done;
  }
  l->n_islands = gb.n_islands;
  hearth_parallel_chunks(R, 32, 0, texel_islands, l);
  hearth_parallel_chunks(mesh->n_triangles, 8192, 0, tri_normals, l);
  if (l->normal_passes > 0 && (s = smooth_normals(l, l->normal_passes, err))) goto done;
  bounding_sphere(mesh, l->sphere);
  l->fan = gb.fan;
  l->pix_dir = gb.pix_dir;
  l->own_pix_dir = gb.own_pix_dir;
  gb.fan = NULL;
  gb.pix_dir = NULL;
  if (!l->pix_dir || gb.nomem)
    s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory for the pixel grid");
done:
  if (gb_started) pthread_join(gb_tid, NULL);
  if (isl_started) pthread_join(isl_tid, NULL);
  if (gb.own_pix_dir) free((void *)gb.pix_dir);
  hearth_ray_fan_free(gb.fan);
  return s;
}

void hearth_map_layout_free(hearth_map_layout *l) {
  if (!l) return;
  free(l->island_of_tri);
  free(l->island_of_texel);
  free(l->tri_normal);
  free(l->cos_normal);
  if (l->own_pix_dir) free((void *)l->pix_dir);
  hearth_ray_fan_free(l->fan);
  free(l);
}

hearth_status hearth_map_layout_new(const hearth_mesh *mesh, const hearth_camera *cam,
                                    const hearth_map_opts *opts_in, hearth_map_layout **out,
                                    hearth_err *err) {
  *out = NULL;
  hearth_map_opts opts;
  if (opts_in) opts = *opts_in;
  else hearth_map_opts_default(&opts);
  if (!mesh || !cam) return hearth_err_set(err, HEARTH_E_ARG, "map: missing mesh or camera");
  if (!mesh->uvs)
    return hearth_err_set(err, HEARTH_E_NOT_FOUND, "map: the mesh has no UVs (TEXCOORD_0)");
  size_t R = opts.resolution;
  if (R < 2 || R > 16384)
    return hearth_err_set(err, HEARTH_E_RANGE, "map: resolution %zu outside 2..16384", R);
  if (opts.pixel_stride < 1) opts.pixel_stride = 1;
  if (cam->width <= 0 || cam->height <= 0)
    return hearth_err_set(err, HEARTH_E_ARG, "map: camera has no size");
  hearth_status s = hearth_mesh_validate(mesh, "map mesh", err);
  if (s) return s;
  hearth_map_layout *l = calloc(1, sizeof *l);
  if (!l) return hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
  l->mesh = mesh;
  l->cam = *cam;
  l->R = R;
  l->stride = (size_t)opts.pixel_stride;
  l->normal_passes = opts.normal_passes > 0 ? opts.normal_passes : 0;
  if ((s = build_layout(l, err))) hearth_map_layout_free(l);
  else *out = l;
  return s;
}
