/* Corrected fusion against a closed form: a plate at one temperature in the
 * plane z = 0, seen along its normal from far away (pixels coarser than the
 * texels, so its splats leave texels between them without a record) and
 * from close by at 65 degrees, where its emissivity has fallen and it reads
 * lower. Every observed texel must read the normal view's temperature: a
 * texel that only the oblique view's splats reached borrows its
 * neighbours' records of the normal view. */
#include "hearth/hearth.h"
#include "map/quad_mesh.h"
#include "test_util.h"

#define RES 256
#define T_PLATE 60.0
#define T_ROOM 22.0
#define OBLIQUE_DEG 65.0
#define OBLIQUE_KEEP 0.6 /* share of the excess over the room read at 65 degrees */

/* one view of the plate [-0.05, 0.05]^2: the plate reads keep of its
   excess, the rest of the scene the room */
static double plate_value(double x, double y, int front, const void *ctx) {
  const double keep = *(const double *)ctx;
  int on = front && fabs(x) <= 0.05 && fabs(y) <= 0.05;
  return on ? T_ROOM + keep * (T_PLATE - T_ROOM) : T_ROOM;
}

static void render(const hearth_camera *cam, const hearth_rigid *T, double keep,
                   hearth_image *img) {
  render_plane_view(cam, T, plate_value, &keep, img);
}

/* a camera at distance r from the origin, tilted by deg from +z about the
   world x axis, looking at the origin (camera x along world x) */
static void look_at_origin(double r, double deg, hearth_rigid *T) {
  const double a = deg * M_PI / 180.0, s = sin(a), c = cos(a);
  /* columns: camera x (world x), y = z cross x, z (towards the origin) */
  double R_[9] = {1, 0, 0, 0, -c, -s, 0, s, -c};
  memcpy(T->R, R_, sizeof R_);
  T->t[0] = 0;
  T->t[1] = r * s;
  T->t[2] = r * c;
}

int main(void) {
  hearth_err err = {0};
  hearth_mesh m = {0};
  CHECK_OK(hearth_mesh_alloc(&m, 4, 2, 1, &err), &err);
  size_t nv = 0, nt = 0;
  add_quad(&m, &nv, &nt, -0.05, 0.05, -0.05, 0.05, 0.0, 1, 0.05, 0.95, 0.05, 0.95);
  hearth_camera cam = {320, 240, 300.0, 300.0, 159.5, 119.5, {0, 0, 0, 0, 0}};
  hearth_rigid Tn, To;
  look_at_origin(0.45, 0.0, &Tn);         /* 1.5 mm pixels, 3.5 texels */
  look_at_origin(0.12, OBLIQUE_DEG, &To); /* 0.4 x 0.95 mm pixels */
  hearth_image in, io;
  render(&cam, &Tn, 1.0, &in);
  render(&cam, &To, OBLIQUE_KEEP, &io);
  hearth_map_view views[2] = {{&in, Tn, 0.0, 0}, {&io, To, 0.0, 0}};
  hearth_map_opts o;
  hearth_map_opts_default(&o);
  o.resolution = RES;
  o.threads = 1;
  o.fusion = HEARTH_FUSE_CORRECTED;

  /* the normal view alone leaves texels between its splats unobserved,
     which the oblique view observes */
  hearth_map_result rn, rb;
  CHECK_OK(hearth_map_views(&m, NULL, &cam, views, 1, &o, &rn, &err), &err);
  CHECK_OK(hearth_map_views(&m, NULL, &cam, views, 2, &o, &rb, &err), &err);
  size_t gaps = 0, n_obs = 0, n_bad = 0;
  double worst = 0;
  for (size_t q = 0; q < (size_t)RES * RES; q++) {
    /* texels 8 mm or more inside the plate's edges, where the normal view
       has no silhouette pixels (its dropped ones reach 3 mm in) */
    double x = -0.05 + ((double)(q % RES) + 0.5 - 0.05 * RES) / (0.9 * RES) * 0.1;
    double y = -0.05 + ((double)(q / RES) + 0.5 - 0.05 * RES) / (0.9 * RES) * 0.1;
    if (rb.mask[q] != HEARTH_TEXEL_OBSERVED || fabs(x) > 0.042 || fabs(y) > 0.042) continue;
    n_obs++;
    gaps += rn.mask[q] != HEARTH_TEXEL_OBSERVED;
    double e = fabs(rb.observed[q] - T_PLATE);
    if (e > worst) worst = e;
    n_bad += e > 0.05;
  }
  CHECK_MSG(n_obs > 15000, "%zu texels observed", n_obs);
  CHECK_MSG(gaps > 1000, "only %zu texels without a record of the normal view", gaps);
  CHECK_MSG(worst < 0.05, "worst |error| %.3f degC; %zu of %zu texels off by more than 0.05", worst,
            n_bad, n_obs);

  /* the same bytes at any thread count */
  hearth_map_result r4;
  o.threads = 4;
  CHECK_OK(hearth_map_views(&m, NULL, &cam, views, 2, &o, &r4, &err), &err);
  CHECK(memcmp(rb.mask, r4.mask, (size_t)RES * RES) == 0);
  CHECK(memcmp(rb.filled, r4.filled, (size_t)RES * RES * sizeof(float)) == 0);

  hearth_map_result_free(&rn);
  hearth_map_result_free(&rb);
  hearth_map_result_free(&r4);
  hearth_image_free(&in);
  hearth_image_free(&io);
  hearth_mesh_free(&m);
  TEST_MAIN_END();
}
