/* Island-bounded fill against brute force: a plate partly outside the
 * image, with a hole in its view cast by a small quad floating above it.
 * Every filled texel must carry the value of an observed texel of its own
 * island at the smallest Euclidean distance (checked against all of them),
 * texels of islands never observed stay unobserved, and the result is the
 * same for 1, 2 and 3 threads. */
#include "hearth/hearth.h"
#include "map/quad_mesh.h"
#include "test_util.h"

#define RES 128

/* island of a texel from the UV rectangles (0 plate, 1 occluder, 2 hidden
 * patch under the plate, -1 none) */
static int island_of(size_t col, size_t row) {
  double u = (col + 0.5) / RES, v = (row + 0.5) / RES;
  if (u >= 0.02 && u <= 0.98 && v >= 0.02 && v <= 0.50) return 0;
  if (u >= 0.10 && u <= 0.30 && v >= 0.60 && v <= 0.80) return 1;
  if (u >= 0.50 && u <= 0.70 && v >= 0.60 && v <= 0.80) return 2;
  return -1;
}

int main(void) {
  hearth_err err = {0};
  hearth_mesh m = {0};
  CHECK_OK(hearth_mesh_alloc(&m, 12, 6, 1, &err), &err);
  size_t nv = 0, nt = 0;
  /* the plate reaches past the image's sides (about +-0.16 m at 0.35 m) */
  add_quad(&m, &nv, &nt, -0.30, 0.30, -0.10, 0.10, 0.0, 1, 0.02, 0.98, 0.02, 0.50);
  add_quad(&m, &nv, &nt, -0.03, 0.04, -0.04, 0.02, 0.08, 1, 0.10, 0.30, 0.60, 0.80);
  add_quad(&m, &nv, &nt, -0.02, 0.02, -0.02, 0.02, -0.05, 1, 0.50, 0.70, 0.60, 0.80);
  hearth_camera cam = {256, 192, 275.0, 276.0, 127.3, 95.8, {-0.2, 0.05, 0.0, 0.0, 0.0}};
  hearth_rigid T = {{1, 0, 0, 0, -1, 0, 0, 0, -1}, {0.0, 0.0, 0.35}};
  /* a distinct value per pixel, so a filled value names its source texel */
  hearth_image img;
  CHECK_OK(hearth_image_alloc(&img, 256, 192, 1, HEARTH_PIX_F32, &err), &err);
  hearth_rng rng;
  hearth_rng_seed(&rng, 7);
  for (size_t i = 0; i < 256 * 192; i++)
    ((float *)img.data)[i] = (float)(10.0 + 50.0 * hearth_rng_uniform(&rng));
  hearth_map_view view = {&img, T};
  hearth_map_opts o;
  hearth_map_opts_default(&o);
  o.resolution = RES;
  o.threads = 1;
  hearth_map_result r;
  CHECK_OK(hearth_map_views(&m, NULL, &cam, &view, 1, &o, &r, &err), &err);

  size_t n_obs[3] = {0}, n_fill[3] = {0}, n_unobs[3] = {0}, bad = 0, wrong_mask = 0;
  for (size_t q = 0; q < (size_t)RES * RES; q++) {
    int isl = island_of(q % RES, q / RES);
    uint8_t mk = r.mask[q];
    if (isl < 0) {
      wrong_mask += mk != HEARTH_TEXEL_NONE;
      continue;
    }
    n_obs[isl] += mk == HEARTH_TEXEL_OBSERVED;
    n_unobs[isl] += mk == HEARTH_TEXEL_UNOBSERVED;
    if (mk != HEARTH_TEXEL_FILLED) continue;
    n_fill[isl]++;
    /* brute force: the smallest distance to an observed texel of the island,
       and whether one at that distance has the filled value */
    long x = (long)(q % RES), y = (long)(q / RES), best = -1;
    int match = 0;
    for (size_t p = 0; p < (size_t)RES * RES; p++) {
      if (r.mask[p] != HEARTH_TEXEL_OBSERVED || island_of(p % RES, p / RES) != isl) continue;
      long dx = (long)(p % RES) - x, dy = (long)(p / RES) - y, d = dx * dx + dy * dy;
      if (best < 0 || d < best) {
        best = d;
        match = 0;
      }
      if (d == best && r.observed[p] == r.filled[q]) match = 1;
    }
    if (!match) bad++;
  }
  printf(
      "plate: %zu observed, %zu filled, %zu unobserved; occluder %zu/%zu/%zu; hidden %zu/%zu/%zu\n",
      n_obs[0], n_fill[0], n_unobs[0], n_obs[1], n_fill[1], n_unobs[1], n_obs[2], n_fill[2],
      n_unobs[2]);
  /* the plate is seen with a hole and cut-off sides: much to fill, around
     and inside the observed region */
  CHECK(n_obs[0] > 1000 && n_fill[0] > 1000 && n_unobs[0] == 0);
  CHECK(n_obs[1] > 100 && n_unobs[1] == 0);
  CHECK(n_obs[2] == 0 && n_fill[2] == 0 && n_unobs[2] > 100);
  CHECK(wrong_mask == 0);
  CHECK_MSG(bad == 0, "%zu filled texels did not take the nearest observed texel of their island",
            bad);

  /* the same bytes for any thread count */
  for (int th = 2; th <= 3; th++) {
    hearth_map_result r2;
    o.threads = th;
    CHECK_OK(hearth_map_views(&m, NULL, &cam, &view, 1, &o, &r2, &err), &err);
    CHECK(!memcmp(r.filled, r2.filled, (size_t)RES * RES * sizeof(float)));
    CHECK(!memcmp(r.mask, r2.mask, (size_t)RES * RES));
    hearth_map_result_free(&r2);
  }
  hearth_map_result_free(&r);
  hearth_image_free(&img);
  hearth_mesh_free(&m);
  TEST_MAIN_END();
}
