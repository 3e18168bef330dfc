/* Mapping against closed forms: quads in the plane z = 0 seen from above,
 * a linear temperature field, occlusion, back-face culling, max fusion,
 * island-bounded filling and thread-count determinism. */
#include "hearth/hearth.h"
#include "map/quad_mesh.h"
#include "test_util.h"

#define RES 320

/* field on the visible quads: T = 20 + 200 x (degC, x in metres) */
static double field(double x) { return 20.0 + 200.0 * x; }

/* the scene's temperatures: the field on the two quads (plus offset), the
 * background elsewhere */
static double scene_value(double x, double y, int front, const void *ctx) {
  (void)front; /* every view looks down at the plane */
  int on_a = x >= -0.12 && x <= -0.02 && y >= -0.05 && y <= 0.05;
  int on_b = x >= 0.02 && x <= 0.12 && y >= -0.05 && y <= 0.05;
  return on_a || on_b ? field(x) + *(const double *)ctx : 22.0;
}

static void render(const hearth_camera *cam, const hearth_rigid *T, double offset,
                   hearth_image *img) {
  render_plane_view(cam, T, scene_value, &offset, img);
}

static void look_down(double cx, double cy, double h, hearth_rigid *T) {
  double R_[9] = {1, 0, 0, 0, -1, 0, 0, 0, -1}; /* cam z -> world -z */
  memcpy(T->R, R_, sizeof R_);
  T->t[0] = cx;
  T->t[1] = cy;
  T->t[2] = h;
}

/* loaders: view v's image copied from ctx's array, or an error naming v */
static hearth_status copy_image(void *ctx, size_t v, hearth_image *img, hearth_err *err) {
  const hearth_image *src = ((hearth_image *const *)ctx)[v];
  hearth_status s = hearth_image_alloc(img, src->width, src->height, src->channels, src->type, err);
  if (!s) memcpy(img->data, src->data, hearth_image_bytes(src));
  return s;
}
/* the loader of load_grid: every GRID_STRIDE-th pixel of every
   GRID_STRIDE-th row of the view's image, subsampled here */
typedef struct grid_src {
  const hearth_image *const *imgs;
  size_t stride;
  size_t win[4]; /* the part of the grid made, {x0, y0, w, h}; w = 0: all of it */
} grid_src;
static hearth_status grid_image(void *ctx, size_t v, hearth_image *img, hearth_err *err) {
  const grid_src *g = ctx;
  const hearth_image *src = g->imgs[v];
  const size_t st = g->stride;
  size_t x0 = g->win[0], y0 = g->win[1], w = g->win[2], h = g->win[3];
  if (!w) w = (src->width + st - 1) / st, h = (src->height + st - 1) / st;
  hearth_status s = hearth_image_alloc(img, w, h, src->channels, src->type, err);
  if (s) return s;
  const float *in = src->data;
  float *out = img->data;
  for (size_t y = 0; y < h; y++)
    for (size_t x = 0; x < w; x++) out[y * w + x] = in[(y0 + y) * st * src->width + (x0 + x) * st];
  return HEARTH_OK;
}
static hearth_status fail_image(void *ctx, size_t v, hearth_image *img, hearth_err *err) {
  (void)ctx;
  memset(img, 0, sizeof *img);
  return hearth_err_set(err, HEARTH_E_IO, "view %zu unreadable", v);
}

int main(void) {
  hearth_err err = {0};
  hearth_mesh m = {0};
  CHECK_OK(hearth_mesh_alloc(&m, 16, 8, 1, &err), &err);
  size_t nv = 0, nt = 0;
  /* island A (left), island B (right), island C hidden under A, quad D
     facing down above B (culled: its back faces the camera) */
  add_quad(&m, &nv, &nt, -0.12, -0.02, -0.05, 0.05, 0.0, 1, 0.05, 0.45, 0.05, 0.45);
  add_quad(&m, &nv, &nt, 0.02, 0.12, -0.05, 0.05, 0.0, 1, 0.55, 0.95, 0.05, 0.45);
  add_quad(&m, &nv, &nt, -0.10, -0.04, -0.03, 0.03, -0.01, 1, 0.05, 0.45, 0.55, 0.95);
  add_quad(&m, &nv, &nt, 0.04, 0.10, -0.03, 0.03, 0.05, 0, 0.55, 0.95, 0.55, 0.95);
  hearth_camera cam = {256, 192, 275.0, 276.0, 127.3, 95.8, {-0.3, 0.12, 0.001, -0.0015, -0.02}};
  hearth_rigid T0, T1;
  look_down(0.0, 0.0, 0.35, &T0);
  look_down(0.01, -0.005, 0.34, &T1);
  hearth_image img0, img1;
  render(&cam, &T0, 0.0, &img0);
  render(&cam, &T1, 1.0, &img1); /* second view reads 1 degC warmer */
  hearth_map_view views[2] = {{&img0, T0}, {&img1, T1}};
  hearth_map_opts o;
  hearth_map_opts_default(&o);
  o.resolution = RES;
  o.threads = 1;

  /* one view: observed texels match the field within the splat footprint */
  hearth_map_result r1;
  CHECK_OK(hearth_map_views(&m, NULL, &cam, views, 1, &o, &r1, &err), &err);
  double texel_m = 0.1 / (0.4 * RES);          /* metres per texel on A and B */
  double bound = 200.0 * 1.5 * texel_m + 1e-3; /* |grad| x (splat reach) */
  double worst = 0;
  size_t n_obs[4] = {0}, n_mask[4] = {0};
  for (size_t row = 0; row < RES; row++)
    for (size_t col = 0; col < RES; col++) {
      size_t q = row * RES + col;
      double u = (col + 0.5) / RES, v = (row + 0.5) / RES;
      n_mask[r1.mask[q]]++;
      int isl = v < 0.5 ? (u < 0.5 ? 0 : 1) : (u < 0.5 ? 2 : 3);
      if (r1.mask[q] == HEARTH_TEXEL_OBSERVED) {
        n_obs[isl]++;
        if (isl < 2) {
          double x = isl == 0 ? -0.12 + (u - 0.05) / 0.4 * 0.1 : 0.02 + (u - 0.55) / 0.4 * 0.1;
          double e = fabs(r1.observed[q] - field(x));
          if (e > worst) worst = e;
        }
      }
      if (r1.mask[q] == HEARTH_TEXEL_FILLED && isl < 2) {
        /* filled values come from the same island's range only */
        double lo = isl == 0 ? field(-0.12) : field(0.02),
               hi = isl == 0 ? field(-0.02) : field(0.12);
        CHECK(r1.filled[q] >= lo - bound && r1.filled[q] <= hi + bound);
      }
      if (r1.mask[q] != HEARTH_TEXEL_OBSERVED) CHECK(isnan(r1.observed[q]));
      if (r1.mask[q] == HEARTH_TEXEL_NONE || r1.mask[q] == HEARTH_TEXEL_UNOBSERVED)
        CHECK(isnan(r1.filled[q]));
    }
  CHECK_MSG(worst <= bound, "max error %.4f > bound %.4f", worst, bound);
  CHECK(n_obs[0] > 1000 && n_obs[1] > 1000);
  CHECK_MSG(n_obs[2] == 0, "hidden island observed at %zu texels", n_obs[2]);
  CHECK_MSG(n_obs[3] == 0, "back-facing quad observed at %zu texels", n_obs[3]);
  CHECK(n_mask[HEARTH_TEXEL_UNOBSERVED] > 0);
  CHECK(r1.n_surface == r1.n_observed + r1.n_filled + r1.n_unobserved);
  CHECK(r1.n_observed + r1.n_filled > 0);
  /* the surface is the four UV rectangles: 4 x (0.4 R)^2 texels */
  CHECK_NEAR((double)r1.n_surface, 4.0 * 0.4 * RES * 0.4 * RES, 4.0 * 4 * 0.4 * RES);

  /* two views with max fusion: where both see, the warmer one wins */
  hearth_map_result r2, r3;
  CHECK_OK(hearth_map_views(&m, NULL, &cam, views, 2, &o, &r2, &err), &err);
  size_t warmer = 0, both = 0;
  for (size_t q = 0; q < (size_t)RES * RES; q++)
    if (r1.mask[q] == HEARTH_TEXEL_OBSERVED && r2.mask[q] == HEARTH_TEXEL_OBSERVED) {
      both++;
      if (r2.observed[q] >= r1.observed[q] + 1.0 - 2.0 * bound) warmer++;
    }
  CHECK(both > 0);
  CHECK_MSG(warmer > 0.95 * both, "max fusion: %zu of %zu texels took the warmer view", warmer,
            both);

  /* the maximum is exactly the larger of the two views' own means (each
     view's mean does not depend on the other view), texel by texel */
  hearth_map_result rb;
  CHECK_OK(hearth_map_views(&m, NULL, &cam, views + 1, 1, &o, &rb, &err), &err);
  size_t exact = 0, either = 0;
  for (size_t q = 0; q < (size_t)RES * RES; q++) {
    int a = r1.mask[q] == HEARTH_TEXEL_OBSERVED, b = rb.mask[q] == HEARTH_TEXEL_OBSERVED;
    CHECK(a || b ? r2.mask[q] == HEARTH_TEXEL_OBSERVED : r2.mask[q] != HEARTH_TEXEL_OBSERVED);
    if (!a && !b) continue;
    either++;
    float want = !b ? r1.observed[q] : !a ? rb.observed[q] : fmaxf(r1.observed[q], rb.observed[q]);
    float want_cos = !b   ? r1.best_cos[q]
                     : !a ? rb.best_cos[q]
                          : fmaxf(r1.best_cos[q], rb.best_cos[q]);
    exact += r2.observed[q] == want && r2.best_cos[q] == want_cos;
  }
  CHECK(either > 0);
  CHECK_MSG(exact == either, "max fusion: %zu of %zu texels are the larger view mean", exact,
            either);
  hearth_map_result_free(&rb);

  /* same bytes for any thread count, with or without the cosines */
  o.threads = 2;
  CHECK_OK(hearth_map_views(&m, NULL, &cam, views, 2, &o, &r3, &err), &err);
  CHECK(!memcmp(r2.mask, r3.mask, (size_t)RES * RES));
  CHECK(!memcmp(r2.filled, r3.filled, (size_t)RES * RES * sizeof(float)));
  CHECK(!memcmp(r2.observed, r3.observed, (size_t)RES * RES * sizeof(float)));
  CHECK(!memcmp(r2.best_cos, r3.best_cos, (size_t)RES * RES * sizeof(float)));
  hearth_map_result_free(&r3);
  o.threads = 3;
  o.skip_best_cos = 1;
  CHECK_OK(hearth_map_views(&m, NULL, &cam, views, 2, &o, &r3, &err), &err);
  CHECK(r3.best_cos == NULL);
  CHECK(!memcmp(r2.mask, r3.mask, (size_t)RES * RES));
  CHECK(!memcmp(r2.observed, r3.observed, (size_t)RES * RES * sizeof(float)));
  CHECK(!memcmp(r2.filled, r3.filled, (size_t)RES * RES * sizeof(float)));
  CHECK(r3.n_observed == r2.n_observed && r3.n_filled == r2.n_filled &&
        r3.n_surface == r2.n_surface);
  hearth_map_result_free(&r3);
  o.skip_best_cos = 0;
  o.fusion = HEARTH_FUSE_MEAN;
  o.threads = 1;
  CHECK_OK(hearth_map_views(&m, NULL, &cam, views, 2, &o, &r3, &err), &err);
  hearth_map_result r4;
  o.threads = 2;
  CHECK_OK(hearth_map_views(&m, NULL, &cam, views, 2, &o, &r4, &err), &err);
  CHECK(!memcmp(r3.filled, r4.filled, (size_t)RES * RES * sizeof(float)));
  hearth_map_result_free(&r4);
  /* a view counted twice: the mean of equal readings is the reading, to
     the float rounding of sums that add each splat's corners in turn (a
     few units in the last place) */
  {
    hearth_map_view twice[2] = {views[0], views[0]};
    hearth_map_result one, two;
    o.threads = 1;
    CHECK_OK(hearth_map_views(&m, NULL, &cam, views, 1, &o, &one, &err), &err);
    o.threads = 2;
    CHECK_OK(hearth_map_views(&m, NULL, &cam, twice, 2, &o, &two, &err), &err);
    CHECK(one.n_observed > 1000 && one.n_observed == two.n_observed);
    CHECK(!memcmp(one.mask, two.mask, (size_t)RES * RES));
    size_t same = 0;
    for (size_t q = 0; q < (size_t)RES * RES; q++)
      same += one.mask[q] != HEARTH_TEXEL_OBSERVED ||
              fabsf(one.observed[q] - two.observed[q]) <= 1e-6f * fabsf(one.observed[q]);
    CHECK_MSG(same == (size_t)RES * RES, "%zu texels differ", (size_t)RES * RES - same);
    hearth_map_result_free(&one);
    hearth_map_result_free(&two);
  }
  /* images made by the loader as the casts reach them: the result of the
     images given, at any thread count; a failed load fails the mapping
     with the lowest failing view's error */
  {
    hearth_image *imgs[2] = {&img0, &img1};
    hearth_map_view lazy[2] = {views[0], views[1]};
    lazy[0].image = lazy[1].image = NULL;
    hearth_map_opts lo = o;
    lo.load = copy_image;
    lo.load_ctx = imgs;
    lo.load_channels = 1;
    for (int t = 1; t <= 2; t++) {
      lo.threads = t;
      CHECK_OK(hearth_map_views(&m, NULL, &cam, lazy, 2, &lo, &r4, &err), &err);
      CHECK(!memcmp(r3.mask, r4.mask, (size_t)RES * RES));
      CHECK(!memcmp(r3.observed, r4.observed, (size_t)RES * RES * sizeof(float)));
      CHECK(!memcmp(r3.filled, r4.filled, (size_t)RES * RES * sizeof(float)));
      CHECK(!memcmp(r3.best_cos, r4.best_cos, (size_t)RES * RES * sizeof(float)));
      hearth_map_result_free(&r4);
    }
    lo.load = fail_image;
    CHECK(hearth_map_views(&m, NULL, &cam, lazy, 2, &lo, &r4, &err) == HEARTH_E_IO);
    CHECK_MSG(strstr(err.msg, "view 0 unreadable") != NULL, "%s", err.msg);
    lazy[0].image = &img0; /* view 1 alone fails */
    CHECK(hearth_map_views(&m, NULL, &cam, lazy, 2, &lo, &r4, &err) == HEARTH_E_IO);
    CHECK_MSG(strstr(err.msg, "view 1 unreadable") != NULL, "%s", err.msg);
    /* a loaded image of another size than the camera's */
    lo.load = copy_image;
    hearth_image *swapped[2] = {&img0, &img0};
    hearth_image tiny;
    CHECK_OK(hearth_image_alloc(&tiny, 8, 8, 1, HEARTH_PIX_F32, &err), &err);
    swapped[1] = &tiny;
    lo.load_ctx = swapped;
    CHECK(hearth_map_views(&m, NULL, &cam, lazy, 2, &lo, &r4, &err) == HEARTH_E_SIZE);
    CHECK(strstr(err.msg, "view 1") != NULL);
    hearth_image_free(&tiny);
    /* load_grid: a loader that makes only the grid's pixels (every 2nd and
       every 3rd pixel: 256 x 192 gives 128 x 96 and 86 x 64) maps what the
       whole images map at that stride; the camera's whole image is then
       refused */
    for (int st = 2; st <= 3; st++) {
      hearth_map_opts go = o;
      go.pixel_stride = st;
      hearth_map_result full, grid;
      CHECK_OK(hearth_map_views(&m, NULL, &cam, views, 2, &go, &full, &err), &err);
      CHECK(full.n_observed > 500);
      grid_src gs = {(const hearth_image *const *)imgs, (size_t)st, {0, 0, 0, 0}};
      go.load = grid_image;
      go.load_ctx = &gs;
      go.load_channels = 1;
      go.load_grid = 1;
      go.threads = 2;
      hearth_map_view lz[2] = {views[0], views[1]};
      lz[0].image = lz[1].image = NULL;
      CHECK_OK(hearth_map_views(&m, NULL, &cam, lz, 2, &go, &grid, &err), &err);
      CHECK(grid.n_observed == full.n_observed && grid.n_filled == full.n_filled);
      CHECK(!memcmp(full.mask, grid.mask, (size_t)RES * RES));
      CHECK(!memcmp(full.observed, grid.observed, (size_t)RES * RES * sizeof(float)));
      CHECK(!memcmp(full.filled, grid.filled, (size_t)RES * RES * sizeof(float)));
      hearth_map_result_free(&grid);
      /* the grid cut to the window of the views' extents grown by the
         silhouette filter's 2 pixels, through the camera cropped to it
         (the colour bake's window): every pixel keeps its ray, and the
         maps are the same */
      {
        const size_t pw = (cam.width + (size_t)st - 1) / (size_t)st,
                     ph = (cam.height + (size_t)st - 1) / (size_t)st;
        size_t u[4] = {SIZE_MAX, 0, SIZE_MAX, 0};
        for (int k = 0; k < 2; k++) {
          size_t b[4];
          CHECK_OK(hearth_ray_fan_extent(&cam, (size_t)st, &m, &views[k].T_world_from_cam, 1.0, b,
                                         &err),
                   &err);
          u[0] = b[0] < u[0] ? b[0] : u[0];
          u[1] = b[1] > u[1] ? b[1] : u[1];
          u[2] = b[2] < u[2] ? b[2] : u[2];
          u[3] = b[3] > u[3] ? b[3] : u[3];
        }
        const size_t x0 = u[0] > 2 ? u[0] - 2 : 0, y0 = u[2] > 2 ? u[2] - 2 : 0,
                     x1 = u[1] + 2 < pw ? u[1] + 2 : pw - 1, y1 = u[3] + 2 < ph ? u[3] + 2 : ph - 1;
        /* a real cut: the window leaves part of the grid out */
        CHECK(u[0] <= u[1] && (x1 - x0 + 1) * (y1 - y0 + 1) < pw * ph);
        hearth_camera crop = cam;
        crop.cx -= (double)(x0 * (size_t)st);
        crop.cy -= (double)(y0 * (size_t)st);
        crop.width = (int)((x1 - x0) * (size_t)st + 1);
        crop.height = (int)((y1 - y0) * (size_t)st + 1);
        grid_src ws = {(const hearth_image *const *)imgs,
                       (size_t)st,
                       {x0, y0, x1 - x0 + 1, y1 - y0 + 1}};
        go.load_ctx = &ws;
        CHECK_OK(hearth_map_views(&m, NULL, &crop, lz, 2, &go, &grid, &err), &err);
        CHECK(!memcmp(full.mask, grid.mask, (size_t)RES * RES));
        CHECK(!memcmp(full.filled, grid.filled, (size_t)RES * RES * sizeof(float)));
        hearth_map_result_free(&grid);
        go.load_ctx = &gs;
      }
      hearth_map_result_free(&full);
      go.load = copy_image;
      go.load_ctx = imgs;
      CHECK(hearth_map_views(&m, NULL, &cam, lz, 2, &go, &grid, &err) == HEARTH_E_SIZE);
      CHECK_MSG(strstr(err.msg, "pixel grid") != NULL, "%s", err.msg);
    }
  }
  /* skip_observed: no observed map, the same filled map and mask (made in
     the observed map's place), for mean and max fusion */
  for (int fu = 0; fu < 2; fu++) {
    hearth_map_opts so = o;
    so.fusion = fu ? HEARTH_FUSE_MAX : HEARTH_FUSE_MEAN;
    so.threads = 2;
    hearth_map_result keep, skip;
    CHECK_OK(hearth_map_views(&m, NULL, &cam, views, 2, &so, &keep, &err), &err);
    so.skip_observed = 1;
    CHECK_OK(hearth_map_views(&m, NULL, &cam, views, 2, &so, &skip, &err), &err);
    CHECK(skip.observed == NULL && skip.filled != NULL);
    CHECK(keep.n_filled > 100 && skip.n_filled == keep.n_filled);
    CHECK(!memcmp(keep.mask, skip.mask, (size_t)RES * RES));
    CHECK(!memcmp(keep.filled, skip.filled, (size_t)RES * RES * sizeof(float)));
    hearth_map_result_free(&keep);
    hearth_map_result_free(&skip);
  }

  /* errors: mesh without UVs, wrong image size */
  float *uvs = m.uvs;
  m.uvs = NULL;
  CHECK(hearth_map_views(&m, NULL, &cam, views, 1, &o, &r4, &err) == HEARTH_E_NOT_FOUND);
  m.uvs = uvs;
  hearth_camera small = cam;
  small.width = 255;
  CHECK(hearth_map_views(&m, NULL, &small, views, 1, &o, &r4, &err) == HEARTH_E_SIZE);
  CHECK(strstr(err.msg, "256x192") != NULL);
  /* an unknown fusion rule is refused, not run */
  hearth_map_opts bad = o;
  bad.fusion = (hearth_fusion)7;
  CHECK(hearth_map_views(&m, NULL, &cam, views, 1, &bad, &r4, &err) == HEARTH_E_ARG);
  CHECK(strstr(err.msg, "fusion") != NULL);

  hearth_map_result_free(&r1);
  hearth_map_result_free(&r2);
  hearth_map_result_free(&r3);
  hearth_image_free(&img0);
  hearth_image_free(&img1);
  hearth_mesh_free(&m);
  TEST_MAIN_END();
}
