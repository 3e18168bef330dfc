/* dynamic temperatures on derived (mapped) assets: a small virtual-rig
 * release with H1's objects is built (hearth build's stages, the true rig
 * standing in for calibration) and H1's networks are made from its
 * derived/ maps (use_ground_truth 0). Every region starts within the
 * observed temperatures of its object's map (read here from mask.npy and
 * temperature_observed.npy: no region of texels without surface, no
 * clamping at the Turbo image's 60 degC); each object's mean temperature
 * (sum C T / sum C) is within 2 degC of its map's mean over the texels
 * with a value (observed or filled), the ground-truth run's printed beside
 * it (the map's distance from the truth is the mapping's matter); the energy
 * bookkeeping holds over 10 thermal minutes; and a collection with the
 * expert succeeds and stores obs/thermal_state. */
#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "hearth/hearth.h"
#include "hearth/release.h"
#include "hearth/sim.h"
#include "hearth/synth.h"
#include "hearth/thermo.h"
#include "sim/sim_env.h"
#include "test_util.h"
#include "test_sim_release.h"

static const char *make_release(const char *dir) {
  hearth_synth_opts so;
  test_sim_release_opts(dir, &so);
  so.seed = 3;
  static const char *cats[] = {"cup", "electric_kettle", "eraser"};
  so.n_categories = 3;
  for (int i = 0; i < 3; i++) so.categories[i] = cats[i];
  so.n_states = 2;
  so.n_views = 4;
  so.threads = 2;
  const char *root = test_sim_release_make(&so);
  hearth_err err = {0};
  /* the true rig as the calibration */
  char a[1400], b[1400];
  snprintf(a, sizeof a, "%s/ground_truth/rig.json", root);
  snprintf(b, sizeof b, "%s/calibration/rig.json", root);
  uint8_t *text = NULL;
  size_t len = 0;
  CHECK_OK(hearth_read_file(a, 1 << 20, &text, &len, &err), &err);
  CHECK_OK(hearth_write_file_atomic(b, text, len, &err), &err);
  free(text);
  hearth_build_opts bo;
  hearth_build_opts_default(&bo);
  bo.resolution = 32;
  bo.rgb_resolution = 64;
  bo.calib_overlays = 0;
  bo.threads = 2;
  bo.jobs = 1;
  bo.quiet = 1;
  hearth_build_report br;
  CHECK_OK(hearth_build_release(root, &bo, &br, &err), &err);
  hearth_build_report_free(&br);
  return root;
}

static hearth_sim_env *make_env(const char *root, int use_gt) {
  hearth_sim_opts o;
  hearth_sim_opts_default(&o);
  o.task = HEARTH_SIM_H1;
  o.release_root = root;
  o.use_ground_truth = use_gt;
  o.renderer = "none";
  o.width = o.height = 16;
  o.render_wrist = 0;
  o.thermal = HEARTH_SIM_THERMAL_DYNAMIC;
  o.thermal_speedup = 60;
  hearth_sim_env *e = NULL;
  hearth_err err = {0};
  CHECK_OK(hearth_sim_env_new(&o, &e, &err), &err);
  return e;
}

/* the range of object k's observed texels in its derived map and the mean
 * of the filled map over the texels with a value (mask 1 or 2) */
static void map_figures(const hearth_sim_env *e, int k, double *lo, double *hi, double *mean) {
  char p[4200];
  hearth_npy m = {0}, t = {0}, f = {0};
  hearth_err err = {0};
  snprintf(p, sizeof p, "%s/mask.npy", e->assets[k].map_dir);
  CHECK_OK(hearth_npy_read(p, &m, &err), &err);
  snprintf(p, sizeof p, "%s/temperature_observed.npy", e->assets[k].map_dir);
  CHECK_OK(hearth_npy_read(p, &t, &err), &err);
  snprintf(p, sizeof p, "%s/temperature_filled.npy", e->assets[k].map_dir);
  CHECK_OK(hearth_npy_read(p, &f, &err), &err);
  *lo = INFINITY, *hi = -INFINITY;
  size_t n = hearth_npy_count(&m), cnt = 0;
  double acc = 0;
  CHECK(n > 0 && n == hearth_npy_count(&t) && n == hearth_npy_count(&f) &&
        m.dtype == HEARTH_NPY_U8 && t.dtype == HEARTH_NPY_F32 && f.dtype == HEARTH_NPY_F32);
  for (size_t i = 0; m.data && t.data && f.data && i < n; i++) {
    uint8_t c = ((const uint8_t *)m.data)[i];
    if (c == 1) {
      double v = ((const float *)t.data)[i];
      if (v < *lo) *lo = v;
      if (v > *hi) *hi = v;
    }
    if (c == 1 || c == 2) acc += ((const float *)f.data)[i], cnt++;
  }
  *mean = cnt ? acc / (double)cnt : NAN;
  hearth_npy_free(&m), hearth_npy_free(&t), hearth_npy_free(&f);
}

int main(void) {
  char dir[1100];
  snprintf(dir, sizeof dir, "%s", test_tmpdir("sim_thermal_derived"));
  const char *root = make_release(dir);
  hearth_sim_env *d = make_env(root, 0), *g = make_env(root, 1);
  if (!d || !g) return 1;
  hearth_err err = {0};
  CHECK_OK(hearth_sim_reset(d, 7, 0, 0, &err), &err);
  CHECK_OK(hearth_sim_reset(g, 7, 0, 0, &err), &err);
  double E0[SIM_NOBJ], cup0 = 0;
  for (int k = 0; k < SIM_NOBJ; k++) {
    const hearth_thermo_net *nd = hearth_sim_thermal_net(d, k), *ng = hearth_sim_thermal_net(g, k);
    CHECK(nd && ng && d->assets[k].map_dir[0] && !g->assets[k].map_dir[0]);
    if (!nd || !ng) return 1;
    E0[k] = hearth_thermo_energy(nd);
    double lo, hi, mm;
    map_figures(d, k, &lo, &hi, &mm);
    for (size_t i = 0; i < nd->n; i++)
      CHECK_MSG(nd->region[i].T >= lo - 1e-4 && nd->region[i].T <= hi + 1e-4,
                "object %d (%s/%s) region %s starts at %.2f degC, its map's observed texels "
                "%.2f..%.2f",
                k, d->assets[k].category, d->assets[k].state, nd->region[i].name, nd->region[i].T,
                lo, hi);
    double md = hearth_thermo_mean_temperature(nd), mg = hearth_thermo_mean_temperature(ng);
    printf(
        "object %d %s/%s: %zu regions, mean %.2f degC; its map: observed %.2f..%.2f, mean "
        "%.2f; ground-truth run %.2f\n",
        k, d->assets[k].category, d->assets[k].state, nd->n, md, lo, hi, mm, mg);
    CHECK_MSG(fabs(md - mm) <= 2.0, "object %d: network %.2f, its map %.2f degC", k, md, mm);
    if (k == 0) cup0 = md;
  }
  /* 10 thermal minutes on the table: energy = booked heat */
  double zero[7] = {0, 0, 0, 0, 0, 0, -1};
  for (int t = 0; t < 200; t++) CHECK_OK(hearth_sim_step(d, zero, &err), &err);
  for (int k = 0; k < SIM_NOBJ; k++) {
    const hearth_thermo_net *n = hearth_sim_thermal_net(d, k);
    double dE = hearth_thermo_energy(n) - E0[k] - hearth_sim_thermal_heat_in(d, k) -
                hearth_sim_thermal_heat_exchanged(d, k);
    CHECK_MSG(fabs(dE) <= 1e-9 * fabs(E0[k]), "object %d: energy off by %.3g J", k, dE);
  }
  CHECK(hearth_thermo_mean_temperature(hearth_sim_thermal_net(d, 0)) <
        cup0 - 1.0); /* the hot cup cooled */
  hearth_sim_env_free(d);
  hearth_sim_env_free(g);

  /* sim collect --thermal dynamic on the derived assets */
  char out[1300];
  snprintf(out, sizeof out, "%s/derived_dynamic.hdf5", dir);
  hearth_sim_collect_opts c;
  hearth_sim_collect_opts_default(&c);
  c.task = HEARTH_SIM_H1;
  c.release_root = root;
  c.use_ground_truth = 0;
  c.layouts = 1;
  c.renderer = "none";
  c.thermal = HEARTH_SIM_THERMAL_DYNAMIC;
  c.thermal_speedup = 60;
  c.quiet = 1;
  c.out_path = out;
  hearth_sim_collect_stats cs;
  CHECK_OK(hearth_sim_collect(&c, &cs, &err), &err);
  CHECK_MSG(cs.successes[0] == 1 && cs.successes[1] == 1, "expert: %d/%d, %d/%d", cs.successes[0],
            cs.attempts[0], cs.successes[1], cs.attempts[1]);
  hid_t f = H5Fopen(out, H5F_ACC_RDONLY, H5P_DEFAULT);
  CHECK(f >= 0);
  if (f >= 0) {
    CHECK(H5Lexists(f, "data/demo_0/obs/thermal_state", H5P_DEFAULT) > 0 &&
          H5Lexists(f, "data/demo_1/obs/thermal_state", H5P_DEFAULT) > 0);
    H5Fclose(f);
  }
  TEST_MAIN_END();
}
