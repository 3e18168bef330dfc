/* the two GL back ends, the shadow switch and the software renderer,
 * through the CLI (MuJoCo binds its GL entry points once per process, so
 * each back end runs in its own process): EGL (Mesa's surfaceless
 * platform on a machine without a GPU, the same llvmpipe rasteriser as
 * OSMesa) renders the same pixels as OSMesa; shadows change the lit RGB
 * views and leave the unlit thermal view exactly as it was; the software
 * renderer (the default) draws what GL draws within a loose image bound;
 * an unknown back end or renderer is refused */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/hearth.h"
#include "hearth/sim.h"
#include "test_util.h"

static const char *make_release(const char *dir) {
  static char root[1200];
  snprintf(root, sizeof root, "%s/release", dir);
  hearth_synth_opts so;
  hearth_synth_opts_default(&so);
  so.ideal = 1; /* closed-form: the clean rig */
  so.out_root = root;
  const char *cats[] = {"cup", "electric_kettle", "eraser"};
  so.n_categories = 3;
  for (int i = 0; i < 3; i++) so.categories[i] = cats[i];
  so.n_states = 2;
  so.states[0] = "neutral", so.states[1] = "hot";
  so.n_views = 2;
  so.triangles = 800;
  so.texture_size = 64;
  so.map_resolution = 32;
  so.calibration = 0;
  so.rgb_full_size = 0;
  so.quiet = 1;
  hearth_err err = {0};
  CHECK_OK(hearth_synth_release(&so, &err), &err);
  return root;
}

static int render(const char *exe, const char *root, const char *out, const char *extra) {
  char cmd[4200];
  snprintf(
      cmd, sizeof cmd,
      "'%s' sim render --task H1 --size 96 --release '%s' --ground-truth --out '%s' %s >/dev/null",
      exe, root, out, extra);
  return system(cmd);
}

/* fraction of differing bytes and mean absolute difference of two PNGs */
static void compare(const char *a, const char *b, double *frac, double *mad) {
  hearth_image ia = {0}, ib = {0};
  hearth_err err = {0};
  *frac = *mad = -1;
  CHECK_OK(hearth_png_read(a, &ia, &err), &err);
  CHECK_OK(hearth_png_read(b, &ib, &err), &err);
  if (ia.data && ib.data && ia.width == ib.width && ia.height == ib.height &&
      ia.channels == ib.channels) {
    size_t n = ia.width * ia.height * ia.channels, diff = 0;
    double s = 0;
    const uint8_t *pa = ia.data, *pb = ib.data;
    for (size_t i = 0; i < n; i++) {
      int d = abs((int)pa[i] - (int)pb[i]);
      diff += d != 0;
      s += d;
    }
    *frac = (double)diff / (double)n;
    *mad = s / (double)n;
  } else {
    CHECK_MSG(0, "%s and %s differ in size", a, b);
  }
  hearth_image_free(&ia);
  hearth_image_free(&ib);
}

int main(void) {
  const char *exe = HEARTH_EXE;
  char dir[1100];
  snprintf(dir, sizeof dir, "%s", test_tmpdir("sim_gl"));
  const char *root = make_release(dir);
  char osm[1300], egl[1300], sh[1300], soft[1300], a[1400], b[1400];
  snprintf(osm, sizeof osm, "%s/osmesa", dir);
  snprintf(soft, sizeof soft, "%s/soft", dir);
  snprintf(egl, sizeof egl, "%s/egl", dir);
  snprintf(sh, sizeof sh, "%s/shadows", dir);
  CHECK(render(exe, root, osm, "--renderer gl --gl osmesa") == 0);
  CHECK(render(exe, root, egl, "--renderer gl --gl egl") == 0);
  CHECK(render(exe, root, sh, "--gl osmesa --shadows") == 0); /* gl: shadows ask for it */
  CHECK(render(exe, root, soft, "") == 0);                    /* the default: soft */

  const char *views[] = {"rgb", "thermal", "wrist"};
  for (int v = 0; v < 3; v++) {
    double frac, mad;
    snprintf(a, sizeof a, "%s/H1_%s.png", osm, views[v]);
    snprintf(b, sizeof b, "%s/H1_%s.png", egl, views[v]);
    compare(a, b, &frac, &mad);
    fprintf(stderr, "osmesa vs egl %-8s: %.5f of bytes differ, mean |d| %.4f\n", views[v], frac,
            mad);
    CHECK_MSG(frac >= 0 && mad < 0.5, "%s: EGL and OSMesa disagree (mean |d| %.3f)", views[v], mad);
    snprintf(b, sizeof b, "%s/H1_%s.png", sh, views[v]);
    compare(a, b, &frac, &mad);
    fprintf(stderr, "shadows off/on %-8s: %.5f of bytes differ, mean |d| %.4f\n", views[v], frac,
            mad);
    if (v == 1) CHECK_MSG(frac == 0, "thermal view changed with shadows (%.5f of bytes)", frac);
    else
      CHECK_MSG(frac > 0.01, "%s view did not change with shadows (%.5f of bytes)", views[v], frac);
    /* software against GL: the same picture, up to edge pixels and
     * interpolation (measured on H1-H3 at 128 px: mean |d| 0.02-0.6) */
    snprintf(b, sizeof b, "%s/H1_%s.png", soft, views[v]);
    compare(a, b, &frac, &mad);
    fprintf(stderr, "gl vs soft %-8s: %.5f of bytes differ, mean |d| %.4f\n", views[v], frac, mad);
    CHECK_MSG(frac >= 0 && mad < 2.0, "%s: the software renderer departs from GL (mean |d| %.3f)",
              views[v], mad);
  }

  /* an unknown back end: refused before anything is rendered */
  char bad[1300], cmd[4200];
  snprintf(bad, sizeof bad, "%s/bad", dir);
  snprintf(
      cmd, sizeof cmd,
      "'%s' sim render --task H1 --size 32 --release '%s' --ground-truth --out '%s' --gl vulkan 2>'%s.err'",
      exe, root, bad, bad);
  CHECK(system(cmd) != 0);
  snprintf(
      cmd, sizeof cmd,
      "'%s' sim render --task H1 --size 32 --release '%s' --ground-truth --out '%s' --renderer vulkan 2>'%s.err'",
      exe, root, bad, bad);
  CHECK(system(cmd) != 0);
  hearth_sim_opts o;
  hearth_sim_opts_default(&o);
  o.release_root = root;
  o.gl = "directx";
  hearth_sim_env *e = NULL;
  hearth_err err = {0};
  CHECK(hearth_sim_env_new(&o, &e, &err) == HEARTH_E_ARG);
  CHECK_MSG(strstr(err.msg, "directx") != NULL, "%s", err.msg);
  CHECK(e == NULL);
  /* shadows need GL: the software renderer refuses them */
  o.gl = NULL, o.renderer = "soft", o.shadows = 1;
  CHECK(hearth_sim_env_new(&o, &e, &err) == HEARTH_E_UNSUPPORTED);
  CHECK(e == NULL);
  TEST_MAIN_END();
}
