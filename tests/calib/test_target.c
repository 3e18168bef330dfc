/* Targets as data: target.json (the paper's numbers, strict reading with the
 * file and key in every error), ordering of each lattice from shuffled,
 * cluttered points (symmetric targets by the image direction, refused near
 * the turn), and detection on frames made to look like real ones (clutter,
 * a wide-angle lens, low contrast, inverted polarity, 8-bit tone-mapped
 * thermal) against the virtual rig's projected truth: >= 90% of the frames
 * with the whole target in view found, none mis-ordered, partial ones
 * refused. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "calib/calib_internal.h"
#include "synth/synth_rig.h"
#include "test_util.h"

static void write_text(const char *path, const char *text) {
  FILE *f = fopen(path, "wb");
  if (!f) return;
  fputs(text, f);
  fclose(f);
}

static void test_default_and_json(const char *dir) {
  hearth_target d = hearth_target_default();
  CHECK(hearth_target_holes(&d) == HEARTH_PLATE_HOLES);
  CHECK(hearth_target_row_step(&d) == HEARTH_PLATE_ROW_STEP_M);
  double xyz[HEARTH_TARGET_MAX_HOLES][3];
  hearth_target_points(&d, xyz);
  int same = 1;
  for (int i = 0; i < HEARTH_PLATE_HOLES; i++) {
    double p[3];
    hearth_plate_hole(i, p);
    same &= !memcmp(p, xyz[i], sizeof p);
  }
  CHECK_MSG(same, "the default target's points are the plate's, bit for bit");
  /* hole counts of the three lattices */
  hearth_target h = {HEARTH_LATTICE_HEX, 6, 8, 0.012, 0.008},
                g = {HEARTH_LATTICE_GRID, 7, 5, 0.015, 0.008};
  CHECK(hearth_target_holes(&h) == 48 && hearth_target_holes(&g) == 35);
  hearth_target_points(&h, xyz);
  CHECK_NEAR(xyz[8][0], 0.006, 1e-15);              /* row 1 shifted by P/2 */
  CHECK_NEAR(xyz[8][1], 0.0103923, 1e-15);          /* rows P sqrt(3)/2 apart */
  CHECK_NEAR(xyz[47][0], 7 * 0.012 + 0.006, 1e-15); /* odd rows keep C holes */
  hearth_target_points(&g, xyz);
  CHECK_NEAR(xyz[34][0], 0.060, 1e-15);
  CHECK_NEAR(xyz[34][1], 0.090, 1e-15);

  char path[4096];
  hearth_err err = {0};
  hearth_target t;
  snprintf(path, sizeof path, "%s/absent.json", dir);
  CHECK_OK(hearth_target_read(path, &t, &err), &err);
  CHECK(hearth_target_is_default(&t));
  snprintf(path, sizeof path, "%s/target.json", dir);
  CHECK_OK(hearth_target_write(path, &g, &err), &err);
  CHECK_OK(hearth_target_read(path, &t, &err), &err);
  CHECK(!memcmp(&t, &g, sizeof t));
  /* python's json reads what was written, with the keys of docs/dataset.md */
  char *text = test_slurp(path, NULL);
  CHECK(text && strstr(text, "\"lattice\": \"grid\"") &&
        strstr(text, "\"hole_diameter_m\": 0.008"));
  CHECK(text && !strstr(text, "thickness_m")); /* a thin plate writes no thickness */
  free(text);
  /* an optional plate thickness round-trips; out of range is refused */
  hearth_target gt = g;
  gt.thickness_m = 0.0045;
  CHECK_OK(hearth_target_write(path, &gt, &err), &err);
  CHECK_OK(hearth_target_read(path, &t, &err), &err);
  CHECK(t.thickness_m == 0.0045 && t.rows == 7 && t.cols == 5);
  gt.thickness_m = 0.2;
  CHECK(hearth_target_write(path, &gt, &err) == HEARTH_E_RANGE);
  CHECK(strstr(err.msg, "thickness_m") != NULL);
  {
    const char *neg =
        "{\"lattice\": \"grid\", \"rows\": 7, \"cols\": 7, \"pitch_m\": 0.015, "
        "\"hole_diameter_m\": 0.008, \"thickness_m\": -0.001}";
    CHECK(hearth_target_parse(neg, strlen(neg), "t.json", &t, &err) == HEARTH_E_RANGE);
    CHECK(strstr(err.msg, "thickness_m") != NULL);
  }
  CHECK_OK(hearth_target_write(path, &g, &err), &err); /* the thin grid again */

  static const struct {
    const char *text, *want;
  } bad[] = {
      {"{\"lattice\": \"grid\", \"rows\": 7, \"cols\": 7, \"pitch_m\": 0.015}", "hole_diameter_m"},
      {"{\"lattice\": \"square\", \"rows\": 7, \"cols\": 7, \"pitch_m\": 0.015, "
       "\"hole_diameter_m\": 0.008}",
       "lattice"},
      {"{\"lattice\": \"grid\", \"rows\": 2, \"cols\": 7, \"pitch_m\": 0.015, "
       "\"hole_diameter_m\": 0.008}",
       "rows"},
      {"{\"lattice\": \"grid\", \"rows\": 7, \"cols\": 7.5, \"pitch_m\": 0.015, "
       "\"hole_diameter_m\": 0.008}",
       "cols"},
      {"{\"lattice\": \"grid\", \"rows\": 7, \"cols\": 7, \"pitch_m\": 0.015, "
       "\"hole_diameter_m\": 0.014}",
       "hole_diameter_m"},
      {"{\"lattice\": \"grid\", \"rows\": 7, \"cols\": 7, \"pitch_m\": -1, "
       "\"hole_diameter_m\": 0.008}",
       "pitch_m"},
      {"{\"lattice\": \"grid\", \"rows\": 40, \"cols\": 40, \"pitch_m\": 0.015, "
       "\"hole_diameter_m\": 0.008}",
       "at most 512"},
      {"{\"lattice\": \"grid\", \"rows\": 7, \"cols\": 7, \"pitch_m\": 0.015, "
       "\"hole_diameter_m\": 0.008, \"colour\": 1}",
       "colour"},
      {"{\"lattice\": \"grid\", \"rows\": 7,", "line 1"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    write_text(path, bad[i].text);
    hearth_err e = {0};
    hearth_status s = hearth_target_read(path, &t, &e);
    CHECK_MSG(s != HEARTH_OK && strstr(e.msg, path) && strstr(e.msg, bad[i].want),
              "case %zu: status %d, message '%s' (want the file and '%s')", i, (int)s, e.msg,
              bad[i].want);
  }
}

/* points of target t seen through a similarity turned by `deg` (image
 * scale 20 px per pitch), shuffled, with far outliers */
static size_t project_target(const hearth_target *t, double deg, double (*truth)[2],
                             double (*pts)[2], hearth_rng *r) {
  double xyz[HEARTH_TARGET_MAX_HOLES][3];
  hearth_target_points(t, xyz);
  size_t n = hearth_target_holes(t);
  double a = deg * 3.14159265358979323846 / 180.0, s = 20.0 / t->pitch_m;
  for (size_t i = 0; i < n; i++) {
    double x = xyz[i][0] - 0.06, y = xyz[i][1] - 0.04;
    truth[i][0] = 600 + s * (cos(a) * x - sin(a) * y) + 0.2 * hearth_rng_normal(r);
    truth[i][1] = 400 + s * (sin(a) * x + cos(a) * y) + 0.2 * hearth_rng_normal(r);
  }
  size_t m = 0;
  for (size_t i = 0; i < n; i++) {
    pts[m][0] = truth[i][0];
    pts[m][1] = truth[i][1];
    m++;
  }
  for (int k = 0; k < 6; k++) { /* clutter far from the target */
    pts[m][0] = hearth_rng_range(r, 0, 60);
    pts[m][1] = hearth_rng_range(r, 0, 800);
    m++;
  }
  for (size_t i = m - 1; i > 0; i--) {
    size_t j = (size_t)(hearth_rng_uniform(r) * (double)(i + 1));
    double tx = pts[i][0], ty = pts[i][1];
    pts[i][0] = pts[j][0];
    pts[i][1] = pts[j][1];
    pts[j][0] = tx;
    pts[j][1] = ty;
  }
  return m;
}

static void test_order(void) {
  hearth_rng r;
  hearth_rng_seed(&r, 5);
  static double truth[HEARTH_TARGET_MAX_HOLES][2], pts[HEARTH_TARGET_MAX_HOLES + 8][2],
      out[HEARTH_TARGET_MAX_HOLES][2];
  const hearth_target targets[4] = {hearth_target_default(),
                                    {HEARTH_LATTICE_HEX, 7, 6, 0.012, 0.008},
                                    {HEARTH_LATTICE_HEX, 6, 8, 0.012, 0.008},
                                    {HEARTH_LATTICE_GRID, 6, 9, 0.015, 0.008}};
  /* symmetric: the even-rowed hex and the grid (half-turn) */
  const int symmetric[4] = {0, 0, 1, 1};
  const double turns[6] = {10, -35, 60, 175, -150, 85};
  for (int k = 0; k < 4; k++)
    for (int a = 0; a < 6; a++) {
      const hearth_target *t = &targets[k];
      size_t n = project_target(t, turns[a], truth, pts, &r), nh = hearth_target_holes(t);
      char why[256];
      int ok = hearth_target_order(t, (const double(*)[2])pts, n, out, why, sizeof why);
      double turn = fabs(turns[a]);
      if (!symmetric[k]) {
        /* asymmetric targets: the true order at any turn */
        CHECK_MSG(ok, "target %d turned %g: %s", k, turns[a], why);
        int same = 1;
        for (size_t i = 0; ok && i < nh; i++)
          same &= out[i][0] == truth[i][0] && out[i][1] == truth[i][1];
        CHECK_MSG(!ok || same, "target %d turned %g: mis-ordered", k, turns[a]);
        continue;
      }
      if (turn > 75 && turn < 105) {
        CHECK_MSG(!ok && strstr(why, "symmetric"), "target %d turned %g: %s", k, turns[a],
                  ok ? "ordered near the turn" : why);
        continue;
      }
      CHECK_MSG(ok, "target %d turned %g: %s", k, turns[a], why);
      /* upright: the true order; upside down: the half-turned order
       * (hole i is the true hole n-1-i, x axis again to the right) */
      int flip = turn > 90, same = 1;
      for (size_t i = 0; ok && i < nh; i++) {
        size_t j = flip ? nh - 1 - i : i;
        same &= out[i][0] == truth[j][0] && out[i][1] == truth[j][1];
      }
      CHECK_MSG(!ok || same, "target %d turned %g: not the image-fixed order", k, turns[a]);
    }
  /* a square grid: a quarter-turn symmetry, fixed within 30 degrees */
  hearth_target sq = {HEARTH_LATTICE_GRID, 7, 7, 0.015, 0.008};
  size_t n = project_target(&sq, 20, truth, pts, &r);
  CHECK(hearth_target_order(&sq, (const double(*)[2])pts, n, out, NULL, 0));
  CHECK(out[0][0] == truth[0][0] && out[48][1] == truth[48][1]);
  n = project_target(&sq, 40, truth, pts, &r);
  CHECK(!hearth_target_order(&sq, (const double(*)[2])pts, n, out, NULL, 0));
}

/* ---- real-looking frames ----------------------------------------------------- */
typedef struct tally {
  int full, found, misordered, partial, partial_found;
} tally;

/* detect one frame and judge it against the truth */
static void judge(const hearth_camera *cam, const synth_plate_geom *g, const hearth_rigid *T,
                  int thermal, int tone8, const synth_plate_look *look, uint64_t seed, tally *ty,
                  const char *what) {
  static double truth[HEARTH_TARGET_MAX_HOLES][2];
  int inside = synth_plate_truth(cam, g, T, truth);
  hearth_image img = {0}, g8 = {0};
  hearth_err err = {0};
  CHECK_OK(synth_plate_frame(cam, g, T, thermal, look, seed, 1, &img, &err), &err);
  hearth_detect_opts o;
  hearth_detect_opts_default(&o);
  o.target = g->t;
  hearth_detection *d = calloc(1, sizeof *d);
  if (thermal && tone8) {
    CHECK_OK(synth_tone_map8(&img, &g8, &err), &err);
    CHECK_OK(hearth_detect_plate_color(&g8, &o, d, &err), &err);
  } else if (thermal) {
    CHECK_OK(hearth_detect_plate_thermal(&img, &o, d, &err), &err);
  } else {
    CHECK_OK(hearth_detect_plate_color(&img, &o, d, &err), &err);
  }
  if (getenv("TARGET_DUMP")) {
    char p[256];
    snprintf(p, sizeof p, "/tmp/tt/%llu.png", (unsigned long long)seed);
    hearth_image v = {0};
    if (thermal) synth_tone_map8(&img, &v, &err);
    hearth_png_write(p, thermal ? &v : &img, &err);
    hearth_image_free(&v);
  }
  /* within a quarter of the hole spacing of the true hole of that index;
   * the spacing in pixels from the truth's first two holes */
  double sp = hypot(truth[1][0] - truth[0][0], truth[1][1] - truth[0][1]);
  if ((size_t)inside == g->n) {
    ty->full++;
    if (d->found) {
      ty->found++;
      double worst = 0;
      for (size_t i = 0; i < g->n; i++)
        worst = fmax(worst, hypot(d->centres[i][0] - truth[i][0], d->centres[i][1] - truth[i][1]));
      if (worst > 0.25 * sp) {
        ty->misordered++;
        fprintf(stderr, "%s: MIS-ORDERED (worst %.2f px, spacing %.2f)\n", what, worst, sp);
      }
    } else {
      fprintf(stderr, "%s: not found: %s\n", what, d->reason);
    }
  } else {
    ty->partial++;
    ty->partial_found += d->found;
  }
  free(d);
  hearth_image_free(&img);
  hearth_image_free(&g8);
}

static void test_real_looking(void) {
  hearth_rig rig;
  synth_rig_draw_thermal(11, 256, 192, 1, &rig); /* wide-angle thermal lens */
  /* a half-size colour camera keeps the test fast */
  hearth_camera rgb = rig.rgb;
  rgb.width /= 2;
  rgb.height /= 2;
  rgb.fx /= 2;
  rgb.fy /= 2;
  rgb.cx = (rgb.cx + 0.5) / 2 - 0.5;
  rgb.cy = (rgb.cy + 0.5) / 2 - 0.5;
  const hearth_target targets[3] = {hearth_target_default(),
                                    {HEARTH_LATTICE_HEX, 6, 8, 0.012, 0.008},
                                    {HEARTH_LATTICE_GRID, 7, 7, 0.015, 0.008}};
  static synth_plate_geom g;
  tally all = {0};
  hearth_rng r;
  hearth_rng_seed(&r, 77);
  for (int k = 0; k < 3; k++) {
    synth_plate_geom_init(&g, &targets[k]);
    double ds = g.half_w / 0.100;
    for (int f = 0; f < 12; f++) {
      int thermal = f % 3 != 2, partial = f % 6 == 5;
      const hearth_camera *cam = thermal ? &rig.thermal : &rgb;
      synth_plate_look look = {1, f % 2, (f / 2) % 2};
      hearth_rigid T;
      static double c[HEARTH_TARGET_MAX_HOLES][2];
      for (int tries = 0; tries < 200; tries++) {
        double d = hearth_rng_range(&r, thermal ? 0.20 : 0.30, thermal ? 0.32 : 0.45) * ds;
        double ox = hearth_rng_range(&r, -0.2, 0.2), oy = hearth_rng_range(&r, -0.12, 0.12);
        if (partial) ox = (hearth_rng_uniform(&r) < 0.5 ? -1 : 1) * hearth_rng_range(&r, 0.5, 0.7);
        synth_plate_pose(&g, &r, d, ox, oy, &T);
        size_t n = (size_t)synth_plate_truth(cam, &g, &T, c);
        if (partial ? (n >= g.n / 4 && n < g.n) : n == g.n) break;
      }
      char what[96];
      snprintf(what, sizeof what, "%s %s frame %d (clutter, low contrast %d, inverted %d)",
               hearth_lattice_name(targets[k].lattice), thermal ? "thermal" : "colour", f,
               look.low_contrast, look.invert);
      judge(cam, &g, &T, thermal, thermal && f % 3 == 1, &look, 1000 + (uint64_t)(k * 100 + f),
            &all, what);
    }
  }
  fprintf(stderr,
          "real-looking frames: %d/%d with the whole target in view found, %d mis-ordered; "
          "%d/%d partial found\n",
          all.found, all.full, all.misordered, all.partial_found, all.partial);
  CHECK(all.full >= 24);
  CHECK_MSG(all.found * 10 >= all.full * 9, "found %d of %d", all.found, all.full);
  CHECK(all.misordered == 0);
  CHECK(all.partial >= 4 && all.partial_found == 0);
}

int main(void) {
  const char *tmp = getenv("HEARTH_TEST_TMP");
  char dir[4096];
  snprintf(dir, sizeof dir, "%s/calib_target", tmp ? tmp : "/tmp");
  mkdir(tmp ? tmp : "/tmp", 0755);
  mkdir(dir, 0755);
  test_default_and_json(dir);
  test_order();
  test_real_looking();
  if (g_test_failures) fprintf(stderr, "%d failure(s)\n", g_test_failures);
  return g_test_failures != 0;
}
