/* hearth's software renderer (src/sim/sim_soft.c) on closed-form scenes:
 * a textured quad facing the camera shows at each pixel the bilinear
 * texel of its known texture coordinate; a sphere under one directional
 * light shows Lambert's max(0, n . l) of its ray-cast normal; of two
 * overlapping quads the nearer one wins in either drawing order, and of
 * nested spheres drawn inner first (more winning triangles than pixels)
 * the outer one alone shows; the
 * thermal twin of a lit pass equals the separate unlit render. Then
 * determinism: a scene of every geom kind rendered in two threads at once
 * gives the main thread's bytes, and (with --write FILE, run by the -O0
 * build of this file and the renderer, tests/CMakeLists) the -O2
 * library's bytes equal the -O0 build's. */
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/sim_soft.h"
#include "test_util.h"

static const char *tmp_dir(void) {
  const char *t = getenv("HEARTH_TEST_TMP");
  return t && *t ? t : "/tmp";
}

static mjModel *load(const char *name, const char *xml) {
  char path[1200], msg[1000] = "";
  snprintf(path, sizeof path, "%s/soft_%s.xml", tmp_dir(), name);
  FILE *f = fopen(path, "w");
  if (!f) return NULL;
  fputs(xml, f);
  fclose(f);
  mjModel *m = mj_loadXML(path, NULL, msg, sizeof msg);
  if (!m) fprintf(stderr, "%s: %s\n", path, msg);
  return m;
}

static sim_soft_view lit_view(int cam) {
  sim_soft_view v = {.cam = cam, .mode = SIM_SOFT_LIT, .only_geom = -1};
  for (int g = 0; g < 6; g++) v.groups[g] = 1;
  return v;
}

/* ---- a textured quad filling the image ------------------------------------- */
static void check_quad(void) {
  /* quad half size 0.1 at z = 0, camera 1 m above looking down, fovy so the
   * quad spans the image exactly */
  double fovy = 2.0 * atan(0.1 / 1.0) * 180.0 / M_PI;
  char xml[2000];
  snprintf(xml, sizeof xml,
           "<mujoco><asset><texture name=\"t\" type=\"2d\" builtin=\"flat\" rgb1=\"0.2 0.3 0.5\" "
           "mark=\"random\" random=\"0.4\" markrgb=\"1 0.9 0.1\" width=\"8\" height=\"8\"/>"
           "<material name=\"m\" texture=\"t\"/></asset><worldbody>"
           "<camera name=\"c\" pos=\"0 0 1\" fovy=\"%.10f\"/>"
           "<geom type=\"box\" size=\"0.1 0.1 0.0005\" pos=\"0 0 -0.0005\" material=\"m\"/>"
           "</worldbody></mujoco>",
           fovy);
  mjModel *m = load("quad", xml);
  CHECK(m != NULL);
  if (!m) return;
  mjData *d = mj_makeData(m);
  mj_forward(m, d);
  int W = 32;
  sim_soft *s = sim_soft_new(m, W, W);
  uint8_t *img = malloc(3 * W * W);
  unsigned char flag[1] = {1};
  sim_soft_view v = lit_view(0);
  v.mode = SIM_SOFT_UNLIT, v.tex_geom = flag;
  sim_soft_render(s, m, d, &v, img, NULL, NULL);
  /* texel lookup of MuJoCo's 2D mapping on a box top: s = 0.5 x/a - 0.5,
   * t = -0.5 y/a - 0.5 (one repeat), bilinear with wrap, texel centres at
   * half-integers, row 0 of the texture at t = 0 */
  const uint8_t *tex = m->tex_rgb + m->tex_adr[0];
  int tw = m->tex_width[0], th = m->tex_height[0];
  int bad = 0;
  double worst = 0;
  for (int y = 1; y < W - 1; y++)
    for (int x = 1; x < W - 1; x++) {
      double wx = ((x + 0.5) / W * 2 - 1) * 0.1, wy = ((y + 0.5) / W * 2 - 1) * 0.1;
      double su = 0.5 * wx / 0.1 - 0.5, tv = -0.5 * wy / 0.1 - 0.5;
      double fu = su * tw - 0.5, fv = tv * th - 0.5;
      int x0 = (int)floor(fu), y0 = (int)floor(fv);
      double ax = fu - x0, ay = fv - y0;
      for (int c = 0; c < 3; c++) {
        double val = 0;
        for (int k = 0; k < 4; k++) {
          int xi = ((x0 + (k & 1)) % tw + tw) % tw, yi = ((y0 + (k >> 1)) % th + th) % th;
          double wgt = ((k & 1) ? ax : 1 - ax) * ((k >> 1) ? ay : 1 - ay);
          val += wgt * tex[3 * (yi * tw + xi) + c];
        }
        double diff = fabs(val - img[3 * (y * W + x) + c]);
        if (diff > worst) worst = diff;
        bad += diff > 1.0;
      }
    }
  CHECK_MSG(bad == 0, "textured quad: %d channel values off the analytic texel by > 1 (worst %.2f)",
            bad, worst);
  /* the corners of the image lie on the quad too: nothing is background */
  CHECK(img[0] | img[1] | img[2]);
  free(img);
  sim_soft_free(s);
  mj_deleteData(d);
  mj_deleteModel(m);
}

/* ---- Lambert sphere ---------------------------------------------------------- */
static void check_sphere(void) {
  /* unit-albedo sphere, no specular, one directional light along
   * (-1, 0, -1)/sqrt 2 (so l = (1, 0, 1)/sqrt 2), no headlight, no ambient;
   * fine tessellation so Gouraud interpolation stays close to the exact
   * shading */
  const char *xml =
      "<mujoco><visual><headlight active=\"0\"/><quality numslices=\"128\" numstacks=\"96\"/>"
      "</visual><asset><material name=\"w\" rgba=\"1 1 1 1\" specular=\"0\" shininess=\"0\"/>"
      "</asset><worldbody><light directional=\"true\" dir=\"-1 0 -1\" diffuse=\"1 1 1\" "
      "ambient=\"0 0 0\" specular=\"0 0 0\"/>"
      "<camera name=\"c\" pos=\"0 0 10\" fovy=\"8\"/>"
      "<geom type=\"sphere\" size=\"0.5\" material=\"w\"/></worldbody></mujoco>";
  mjModel *m = load("sphere", xml);
  CHECK(m != NULL);
  if (!m) return;
  mjData *d = mj_makeData(m);
  mj_forward(m, d);
  int W = 96;
  sim_soft *s = sim_soft_new(m, W, W);
  uint8_t *img = malloc(3 * W * W);
  sim_soft_view v = lit_view(0);
  sim_soft_render(s, m, d, &v, img, NULL, NULL);
  double f = 0.5 * W / tan(4.0 * M_PI / 180.0), l[3] = {M_SQRT1_2, 0, M_SQRT1_2};
  int n = 0, bad = 0, inside_bg = 0;
  double sum = 0;
  for (int y = 0; y < W; y++)
    for (int x = 0; x < W; x++) {
      /* the pixel centre's ray from (0, 0, 10) and its sphere hit */
      double dir[3] = {(x + 0.5 - 0.5 * W) / f, (y + 0.5 - 0.5 * W) / f, -1};
      double dn = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + 1);
      for (int k = 0; k < 3; k++) dir[k] /= dn;
      double o[3] = {0, 0, 10}, b = o[2] * dir[2], c = 100 - 0.25, disc = b * b - c;
      const uint8_t *p = img + 3 * (y * W + x);
      if (disc < 0.02) continue; /* off the sphere or at its rim */
      double t = -b - sqrt(disc), nrm[3];
      for (int k = 0; k < 3; k++) nrm[k] = (o[k] + t * dir[k]) / 0.5;
      double lam = nrm[0] * l[0] + nrm[1] * l[1] + nrm[2] * l[2];
      double want = 255.0 * (lam > 0 ? lam : 0);
      inside_bg += p[0] == 0 && p[1] == 0 && p[2] == 0 && want > 20;
      if (lam < 0.08) continue; /* the terminator: Gouraud clamps at the vertices */
      double e = fabs(p[0] - want);
      sum += e, n++;
      bad += e > 3.0 || p[0] != p[1] || p[1] != p[2];
    }
  CHECK_MSG(n > 2000, "sphere: only %d lit pixels", n);
  CHECK_MSG(bad == 0, "sphere: %d of %d pixels off Lambert's law by > 3 levels", bad, n);
  CHECK_MSG(n > 0 && sum / n < 1.0, "sphere: mean error %.2f levels", n ? sum / n : 0.0);
  CHECK_MSG(inside_bg == 0, "sphere: %d lit pixels left as background", inside_bg);
  free(img);
  sim_soft_free(s);
  mj_deleteData(d);
  mj_deleteModel(m);
}

/* ---- depth order --------------------------------------------------------------- */
static void check_depth(int near_first) {
  /* quad A (x < 0.05) at z = 0.2, quad B (x > -0.05) at z = 0; seen from
   * above the overlap shows A whichever the model lists first */
  const char *qa = "<geom name=\"a\" type=\"box\" size=\"0.1 0.1 0.001\" pos=\"-0.05 0 0.2\"/>";
  const char *qb = "<geom name=\"b\" type=\"box\" size=\"0.1 0.1 0.001\" pos=\"0.05 0 0\"/>";
  char xml[2000];
  snprintf(xml, sizeof xml,
           "<mujoco><worldbody><camera name=\"c\" pos=\"0 0 2\" fovy=\"10\"/>%s%s</worldbody>"
           "</mujoco>",
           near_first ? qa : qb, near_first ? qb : qa);
  mjModel *m = load(near_first ? "depth1" : "depth2", xml);
  CHECK(m != NULL);
  if (!m) return;
  mjData *d = mj_makeData(m);
  mj_forward(m, d);
  int W = 64, ga = mj_name2id(m, mjOBJ_GEOM, "a"), gb = mj_name2id(m, mjOBJ_GEOM, "b");
  sim_soft *s = sim_soft_new(m, W, W);
  int *ids = malloc(sizeof(int) * W * W);
  sim_soft_view v = lit_view(0);
  v.mode = SIM_SOFT_SEGMENT;
  sim_soft_render(s, m, d, &v, NULL, NULL, ids);
  double f = 0.5 * W / tan(5.0 * M_PI / 180.0);
  int wrong = 0;
  for (int y = 0; y < W; y++)
    for (int x = 0; x < W; x++) {
      /* the pixel centre's ray meets z = top of A (2 - 0.201 below the
       * camera) and z = top of B (2 - 0.001) at these x, y */
      double rx = (x + 0.5 - 0.5 * W) / f, ry = (y + 0.5 - 0.5 * W) / f;
      double xa = rx * (2 - 0.201), ya = ry * (2 - 0.201), xb = rx * 1.999, yb = ry * 1.999;
      int in_a = fabs(xa + 0.05) < 0.1 && fabs(ya) < 0.1,
          in_b = fabs(xb - 0.05) < 0.1 && fabs(yb) < 0.1;
      /* pixels within a hair of an edge are not judged */
      int edge = fabs(fabs(xa + 0.05) - 0.1) < 2e-3 || fabs(fabs(ya) - 0.1) < 2e-3 ||
                 fabs(fabs(xb - 0.05) - 0.1) < 2e-3 || fabs(fabs(yb) - 0.1) < 2e-3;
      if (edge) continue;
      int want = in_a ? ga : in_b ? gb : -1;
      wrong += ids[y * W + x] != want;
    }
  CHECK_MSG(wrong == 0, "depth order (%s first): %d pixels show the wrong quad",
            near_first ? "near" : "far", wrong);
  free(ids);
  sim_soft_free(s);
  mj_deleteData(d);
  mj_deleteModel(m);
}

/* ---- layers drawn far to near ----------------------------------------------------- */
static void check_layers(void) {
  /* four concentric spheres with the same centre, so drawn in the order
   * listed: the smallest first, every larger one then wins the pixels
   * again. At 8 x 8 pixels more triangles win pixels than there are
   * pixels, so the renderer must drop records no pixel keeps; the image
   * must still be the outer sphere's alone */
  const char *xml =
      "<mujoco><visual><quality numslices=\"64\" numstacks=\"48\"/></visual>"
      "<asset><material name=\"w\" rgba=\"0.8 0.6 0.4 1\"/></asset><worldbody>"
      "<light pos=\"1 1 5\" dir=\"-0.2 -0.2 -1\"/><camera name=\"c\" pos=\"0 0 10\" fovy=\"6\"/>"
      "<geom type=\"sphere\" size=\"0.2\" rgba=\"1 0 0 1\"/>"
      "<geom type=\"sphere\" size=\"0.3\" rgba=\"0 1 0 1\"/>"
      "<geom type=\"sphere\" size=\"0.4\" rgba=\"0 0 1 1\"/>"
      "<geom name=\"outer\" type=\"sphere\" size=\"0.5\" material=\"w\"/>"
      "</worldbody></mujoco>";
  mjModel *m = load("layers", xml);
  CHECK(m != NULL);
  if (!m) return;
  mjData *d = mj_makeData(m);
  mj_forward(m, d);
  const int W = 8;
  int outer = mj_name2id(m, mjOBJ_GEOM, "outer");
  sim_soft *s = sim_soft_new(m, W, W);
  uint8_t *all = malloc(3 * W * W), *alone = malloc(3 * W * W), *inner = malloc(3 * W * W);
  int *ids = malloc(sizeof(int) * W * W);
  sim_soft_view v = lit_view(0);
  sim_soft_render(s, m, d, &v, all, NULL, ids);
  v.only_geom = outer;
  sim_soft_render(s, m, d, &v, alone, NULL, NULL);
  v.only_geom = 0;
  sim_soft_render(s, m, d, &v, inner, NULL, NULL);
  int covered = 0, wrong_id = 0, inner_px = 0;
  for (int i = 0; i < W * W; i++) {
    covered += ids[i] >= 0;
    wrong_id += ids[i] >= 0 && ids[i] != outer;
    inner_px += inner[3 * i] > 0;
  }
  CHECK_MSG(covered > W * W / 2 && inner_px >= 4, "layers: %d pixels covered, %d by the inner",
            covered, inner_px);
  CHECK_MSG(wrong_id == 0, "layers: %d pixels show an inner sphere", wrong_id);
  CHECK_MSG(memcmp(all, alone, 3 * (size_t)W * W) == 0,
            "layers: the scene differs from its outer sphere alone");
  free(all), free(alone), free(inner), free(ids);
  sim_soft_free(s);
  mj_deleteData(d);
  mj_deleteModel(m);
}

/* ---- the determinism scene ------------------------------------------------------ */
/* every geom kind the sim draws, lit by the headlight and a spot light,
 * checker-textured floor, a textured mesh with its own coordinates and a
 * thermal-style twin of it */
static const char *k_scene =
    "<mujoco><visual><headlight ambient=\"0.35 0.35 0.35\" diffuse=\"0.45 0.45 0.45\" "
    "specular=\"0.1 0.1 0.1\"/></visual><asset>"
    "<texture name=\"chk\" type=\"2d\" builtin=\"checker\" rgb1=\"0.9 0.9 0.8\" rgb2=\"0.3 0.3 0.35\" "
    "width=\"64\" height=\"64\"/>"
    "<texture name=\"grad\" type=\"2d\" builtin=\"gradient\" rgb1=\"1 0 0\" rgb2=\"0 0 1\" "
    "width=\"32\" height=\"32\"/>"
    "<material name=\"floor\" texture=\"chk\" texrepeat=\"6 6\"/>"
    "<material name=\"tex\" texture=\"grad\" specular=\"0.15\" shininess=\"0.2\"/>"
    "<material name=\"th\" texture=\"chk\" emission=\"1\" specular=\"0\"/>"
    "<material name=\"white\" rgba=\"0.92 0.92 0.92 1\" specular=\"0.3\"/>"
    "<mesh name=\"tet\" vertex=\"0 0 0  0.1 0 0  0 0.1 0  0 0 0.1\" "
    "texcoord=\"0 0  1 0  0 1  0.5 0.5\" face=\"0 2 1  0 1 3  0 3 2  1 2 3\"/>"
    "</asset><worldbody>"
    "<light pos=\"0.3 0.6 2.6\" dir=\"-0.2 -0.4 -1\" diffuse=\"0.5 0.5 0.5\"/>"
    "<camera name=\"c\" pos=\"0.9 0 0.9\" xyaxes=\"0 1 0 -0.6 0 0.8\" fovy=\"45\"/>"
    "<geom type=\"box\" size=\"3 3 0.01\" pos=\"0 0 -0.01\" material=\"floor\" group=\"0\"/>"
    "<geom type=\"box\" size=\"0.1 0.15 0.05\" pos=\"0 -0.2 0.05\" euler=\"0 0 0.4\" "
    "material=\"white\" group=\"1\"/>"
    "<geom type=\"capsule\" fromto=\"0 0.2 0.05 0.1 0.35 0.3\" size=\"0.04\" material=\"white\" "
    "group=\"1\"/>"
    "<geom type=\"cylinder\" size=\"0.05 0.08\" pos=\"-0.2 0.1 0.08\" rgba=\"0.2 0.6 0.3 1\" "
    "group=\"1\"/>"
    "<geom type=\"sphere\" size=\"0.06\" pos=\"0.15 0.05 0.06\" rgba=\"0.8 0.4 0.1 1\" group=\"1\"/>"
    "<body pos=\"0.1 -0.05 0\" euler=\"0 0 0.7\">"
    "<geom name=\"mesh_rgb\" type=\"mesh\" mesh=\"tet\" material=\"tex\" group=\"2\"/>"
    "<geom name=\"mesh_th\" type=\"mesh\" mesh=\"tet\" material=\"th\" group=\"3\"/></body>"
    "</worldbody></mujoco>";

typedef struct scene_job {
  const mjModel *m;
  const mjData *d;
  int w;
  uint8_t *rgb, *twin, *th;
} scene_job;

/* the scene's lit view with its twin, and the separate unlit view */
static void render_scene(scene_job *j) {
  const mjModel *m = j->m;
  int gr = mj_name2id(m, mjOBJ_GEOM, "mesh_rgb"), gt = mj_name2id(m, mjOBJ_GEOM, "mesh_th");
  sim_soft *s = sim_soft_new(m, j->w, j->w);
  if (!s) return;
  int *twin_tex = malloc(sizeof(int) * m->ngeom);
  unsigned char *flag = calloc(m->ngeom, 1);
  for (int g = 0; g < m->ngeom; g++) twin_tex[g] = -1;
  twin_tex[gr] = m->mat_texid[m->geom_matid[gt]];
  flag[gt] = 1;
  sim_soft_view v = lit_view(0);
  v.groups[3] = 0, v.twin_tex = twin_tex;
  v.flat_rgb[0] = 40, v.flat_rgb[1] = 200, v.flat_rgb[2] = 230;
  sim_soft_render(s, m, j->d, &v, j->rgb, j->twin, NULL);
  sim_soft_view u = v;
  u.mode = SIM_SOFT_UNLIT, u.groups[2] = 0, u.groups[3] = 1, u.tex_geom = flag;
  sim_soft_render(s, m, j->d, &u, j->th, NULL, NULL);
  free(twin_tex), free(flag);
  sim_soft_free(s);
}

static void *scene_thread(void *arg) {
  render_scene(arg);
  return NULL;
}

static int alloc_job(scene_job *j, const mjModel *m, const mjData *d, int w) {
  j->m = m, j->d = d, j->w = w;
  j->rgb = calloc(3 * w * w, 1), j->twin = calloc(3 * w * w, 1), j->th = calloc(3 * w * w, 1);
  return j->rgb && j->twin && j->th;
}

static void free_job(scene_job *j) { free(j->rgb), free(j->twin), free(j->th); }

int main(int argc, char **argv) {
  const char *write_to = argc == 3 && strcmp(argv[1], "--write") == 0 ? argv[2] : NULL;
  mjModel *m = load(write_to ? "scene_O0" : "scene", k_scene);
  CHECK(m != NULL);
  if (!m) return 1;
  mjData *d = mj_makeData(m);
  mj_forward(m, d);
  const int W = 96;
  size_t n = 3 * (size_t)W * W;
  scene_job main_job;
  CHECK(alloc_job(&main_job, m, d, W));
  render_scene(&main_job);
  if (write_to) {
    /* the -O0 build: hand the bytes to the -O2 test */
    FILE *f = fopen(write_to, "wb");
    CHECK(f && fwrite(main_job.rgb, 1, n, f) == n && fwrite(main_job.twin, 1, n, f) == n &&
          fwrite(main_job.th, 1, n, f) == n);
    if (f) fclose(f);
    free_job(&main_job);
    mj_deleteData(d);
    mj_deleteModel(m);
    return g_test_failures;
  }
  check_quad();
  check_sphere();
  check_depth(1);
  check_depth(0);
  check_layers();
  /* the scene is not empty and not flat */
  long lit = 0;
  for (size_t i = 0; i < n; i++) lit += main_job.rgb[i] != main_job.rgb[i % 3];
  CHECK_MSG(lit > (long)n / 4, "scene: only %ld values differ from the first pixel's", lit);
  /* the twin of the lit pass is the separate unlit render */
  CHECK_MSG(memcmp(main_job.twin, main_job.th, n) == 0,
            "the thermal twin differs from the unlit render");
  /* two threads at once, each with its own context: the same bytes */
  scene_job tj[2];
  pthread_t th[2];
  for (int i = 0; i < 2; i++) {
    CHECK(alloc_job(&tj[i], m, d, W));
    CHECK(pthread_create(&th[i], NULL, scene_thread, &tj[i]) == 0);
  }
  for (int i = 0; i < 2; i++) {
    pthread_join(th[i], NULL);
    CHECK_MSG(memcmp(tj[i].rgb, main_job.rgb, n) == 0 &&
                  memcmp(tj[i].twin, main_job.twin, n) == 0 &&
                  memcmp(tj[i].th, main_job.th, n) == 0,
              "thread %d rendered other bytes", i);
    free_job(&tj[i]);
  }
  /* the -O0 build's bytes (written by sim/test_sim_soft_O0 before this test) */
  const char *o0 = getenv("HEARTH_SOFT_O0_IMAGE");
  if (o0) {
    FILE *f = fopen(o0, "rb");
    CHECK_MSG(f != NULL, "%s: the -O0 build's images are missing", o0);
    if (f) {
      uint8_t *b = malloc(3 * n);
      size_t got = fread(b, 1, 3 * n, f);
      fclose(f);
      CHECK_MSG(got == 3 * n, "%s: %zu bytes, expected %zu", o0, got, 3 * n);
      if (got == 3 * n) {
        size_t diff = 0;
        for (size_t i = 0; i < n; i++)
          diff += (b[i] != main_job.rgb[i]) + (b[n + i] != main_job.twin[i]) +
                  (b[2 * n + i] != main_job.th[i]);
        CHECK_MSG(diff == 0, "-O0 and -O2 builds differ in %zu bytes", diff);
      }
      free(b);
    }
  }
  free_job(&main_job);
  mj_deleteData(d);
  mj_deleteModel(m);
  return g_test_failures;
}
