/* dynamic temperatures in the simulator: a hot cup left alone follows its
 * own network's backward Euler integration, a finger contact cools the
 * region it touches faster than an untouched one, the energy balance holds
 * with contacts, an object stacked on the hot cup takes the heat the cup
 * gives through their link (energy conserved, no overshoot at any step
 * size), the rendered thermal view of a cooling cup gets colder,
 * and static collections are the bytes of ones made without the option
 * while dynamic ones add obs/thermal_state beside the same motion. */
#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/image.h"
#include "hearth/sim.h"
#include "hearth/thermo.h"
#include "sim/sim_env.h"
#include "test_util.h"
#include "test_sim_release.h"

/* mean temperature (inverted Turbo, 10..60 degC) of the pixels in sel */
static double image_mean_temp(const uint8_t *rgb, const uint8_t *sel, size_t n) {
  uint8_t lut[501][3];
  for (int i = 0; i < 501; i++) hearth_turbo(i / 500.0, lut[i]);
  double acc = 0;
  size_t cnt = 0;
  for (size_t p = 0; p < n; p++) {
    if (!sel[p]) continue;
    int best = 0, bd = 1 << 30;
    for (int j = 0; j < 501; j++) {
      int d0 = rgb[3 * p] - lut[j][0], d1 = rgb[3 * p + 1] - lut[j][1],
          d2 = rgb[3 * p + 2] - lut[j][2];
      int d = d0 * d0 + d1 * d1 + d2 * d2;
      if (d < bd) bd = d, best = j;
    }
    acc += 10.0 + 50.0 * best / 500.0, cnt++;
  }
  return cnt ? acc / (double)cnt : NAN;
}

static void write_png(const char *path, const uint8_t *rgb, int w, int h) {
  hearth_image img = {0};
  hearth_err err = {0};
  CHECK_OK(hearth_image_alloc(&img, (size_t)w, (size_t)h, 3, HEARTH_PIX_U8, &err), &err);
  /* the sim's rows are bottom first; PNG rows top first */
  for (int y = 0; y < h; y++)
    memcpy((uint8_t *)img.data + (size_t)y * w * 3, rgb + (size_t)(h - 1 - y) * w * 3,
           (size_t)w * 3);
  CHECK_OK(hearth_png_write(path, &img, &err), &err);
  hearth_image_free(&img);
  printf("wrote %s\n", path);
}

static hearth_sim_env *make_env_o(const char *root, double h_table, double h_finger,
                                  double h_object, double speedup, int size, const char *renderer) {
  hearth_sim_opts o;
  hearth_sim_opts_default(&o);
  o.renderer = renderer;
  o.task = HEARTH_SIM_H1;
  o.release_root = root;
  o.width = o.height = size;
  o.render_wrist = 0;
  o.thermal = HEARTH_SIM_THERMAL_DYNAMIC;
  o.h_contact_table = h_table, o.h_contact_finger = h_finger, o.h_contact_object = h_object;
  o.thermal_speedup = speedup;
  hearth_sim_env *e = NULL;
  hearth_err err = {0};
  CHECK_OK(hearth_sim_env_new(&o, &e, &err), &err);
  return e;
}

static hearth_sim_env *make_env_r(const char *root, double h_table, double h_finger, double speedup,
                                  int size, const char *renderer) {
  return make_env_o(root, h_table, h_finger, 0, speedup, size, renderer);
}

static hearth_sim_env *make_env(const char *root, double h_table, double h_finger, double speedup,
                                int size) {
  return make_env_r(root, h_table, h_finger, speedup, size, "soft");
}

/* MuJoCo's GL renderer (OSMesa) shows the re-uploaded texture too: the
 * hot cup's pixels get colder after 20 steps of 30 s each */
static void check_gl(const char *root) {
  hearth_err err = {0};
  const int S = 64;
  hearth_sim_env *e = make_env_r(root, 0, 0, 600.0, S, "gl");
  if (!e) return;
  CHECK_OK(hearth_sim_reset(e, 7, 0, 0, &err), &err);
  hearth_sim_obs ob;
  size_t npx = (size_t)S * S;
  uint8_t *a = malloc(npx * 3), *sel = calloc(npx, 1);
  CHECK_OK(hearth_sim_observe(e, &ob, &err), &err);
  memcpy(a, ob.agentview_thermal, npx * 3);
  for (size_t p = 0; p < npx; p++) {
    uint8_t one = 1;
    sel[p] = image_mean_temp(a + 3 * p, &one, 1) > 35.0;
  }
  double zero[7] = {0, 0, 0, 0, 0, 0, -1};
  for (int t = 0; t < 20; t++) CHECK_OK(hearth_sim_step(e, zero, &err), &err);
  CHECK_OK(hearth_sim_observe(e, &ob, &err), &err);
  double t0 = image_mean_temp(a, sel, npx), t1 = image_mean_temp(ob.agentview_thermal, sel, npx);
  printf("gl: hot pixels %.2f -> %.2f degC after 10 thermal minutes\n", t0, t1);
  CHECK_MSG(t1 < t0 - 1.0, "gl thermal view %.2f -> %.2f", t0, t1);
  free(a), free(sel);
  hearth_sim_env_free(e);
}

/* the hot cup (object 0 of H1) with no contact links: the env's state at
 * every step is the thermo library's integration of the network it
 * started from; the rendered cup gets colder; PNGs at three moments */
static void check_alone(const char *root, const char *dir) {
  hearth_err err = {0};
  const int S = 96, steps = 200;
  hearth_sim_env *e = make_env(root, 0, 0, 60.0, S);
  if (!e) return;
  CHECK_OK(hearth_sim_reset(e, 7, 0, 0, &err), &err);
  const hearth_thermo_net *net = hearth_sim_thermal_net(e, 0);
  CHECK(net && net->n >= 2);
  if (!net) return;
  hearth_thermo_net ref = *net;
  double T_hot0 = 0;
  double E0 = hearth_thermo_energy(&ref);
  size_t hot = 0;
  for (size_t i = 1; i < ref.n; i++)
    if (ref.region[i].T > ref.region[hot].T) hot = i;
  CHECK_MSG(ref.region[hot].T > 35.0, "the hot cup starts at %.1f degC", ref.region[hot].T);
  T_hot0 = ref.region[hot].T;
  size_t ncol = hearth_sim_thermal_state(e, NULL, 0);
  CHECK(ncol >= net->n);
  float *col = malloc(ncol * sizeof(float));
  size_t npx = (size_t)S * S;
  uint8_t *sel = calloc(npx, 1), *first = malloc(npx * 3);
  double zero[7] = {0, 0, 0, 0, 0, 0, -1}, max_dev = 0, img_T[3] = {0};
  int boxes[2][4];
  CHECK_OK(hearth_sim_candidate_boxes(e, boxes, &err), &err);
  int slot = -1;
  hearth_sim_obs ob;
  for (int t = 0; t <= steps; t++) {
    if (t == 0 || t == steps / 2 || t == steps) {
      CHECK_OK(hearth_sim_observe(e, &ob, &err), &err);
      if (t == 0) {
        memcpy(first, ob.agentview_thermal, npx * 3);
        /* the cup's pixels: hotter than 30 degC at the start, in either
         * candidate box (only the hot cup is) */
        for (int b = 0; b < 2; b++)
          for (int y = boxes[b][1]; y <= boxes[b][3]; y++)
            for (int x = boxes[b][0]; x <= boxes[b][2]; x++) {
              size_t p = (size_t)y * S + x;
              uint8_t one = 1;
              if (image_mean_temp(first + 3 * p, &one, 1) > 30.0) sel[p] = 1, slot = b;
            }
      }
      int m = t == 0 ? 0 : t == steps ? 2 : 1;
      img_T[m] = image_mean_temp(ob.agentview_thermal, sel, npx);
      char p[1400];
      snprintf(p, sizeof p, "%s/thermal_dynamic_step%03d.png", dir, t);
      write_png(p, ob.agentview_thermal, S, S);
    }
    if (t == steps) break;
    CHECK_OK(hearth_sim_step(e, zero, &err), &err);
    CHECK_OK(hearth_thermo_step(&ref, 60.0 / HEARTH_SIM_CONTROL_HZ, NULL, &err), &err);
    net = hearth_sim_thermal_net(e, 0);
    CHECK(net->n_contacts == 0);
    hearth_sim_thermal_state(e, col, ncol);
    for (size_t i = 0; i < ref.n; i++) {
      double d = fabs(net->region[i].T - ref.region[i].T);
      double df = fabs((double)col[i] - ref.region[i].T);
      if (d > max_dev) max_dev = d;
      CHECK_MSG(df <= 1e-5 * fabs(ref.region[i].T) + 1e-6,
                "step %d region %zu stored %.7f ref %.7f", t, i, col[i], ref.region[i].T);
    }
  }
  CHECK_MSG(max_dev <= 1e-9, "env vs library: %.3g degC", max_dev);
  /* the cup cooled: energy lost equals the heat the env booked */
  double E = hearth_thermo_energy(hearth_sim_thermal_net(e, 0)),
         q = hearth_sim_thermal_heat_in(e, 0);
  CHECK_MSG(E < E0 && fabs(E - E0 - q) <= 1e-9 * fabs(E0), "E0 %.6f E %.6f heat_in %.6f", E0, E, q);
  size_t nsel = 0;
  for (size_t p = 0; p < npx; p++) nsel += sel[p];
  CHECK_MSG(nsel > 20, "hot cup pixels: %zu", nsel);
  printf(
      "hot cup (slot %c, %zu px): image mean %.2f -> %.2f -> %.2f degC over %d steps (x60: "
      "%.0f s); hottest region %.2f -> %.2f degC\n",
      slot >= 0 ? 'A' + slot : '?', nsel, img_T[0], img_T[1], img_T[2], steps,
      steps * 60.0 / HEARTH_SIM_CONTROL_HZ, T_hot0, hearth_sim_thermal_net(e, 0)->region[hot].T);
  CHECK_MSG(img_T[2] < img_T[1] && img_T[1] < img_T[0], "image mean %.3f %.3f %.3f", img_T[0],
            img_T[1], img_T[2]);
  free(col), free(sel), free(first);
  hearth_sim_env_free(e);
}

/* the expert grasps the hot cup: with finger links the region the pads
 * touch drops further below its no-contact twin than an untouched region,
 * and the energy balance holds at every step */
static void check_finger(const char *root) {
  hearth_err err = {0};
  hearth_sim_env *e[2] = {make_env(root, 0, HEARTH_SIM_H_CONTACT, 10.0, 48),
                          make_env(root, 0, 0, 10.0, 48)};
  if (!e[0] || !e[1]) return;
  int touched[HEARTH_THERMO_MAX_REGIONS] = {0};
  double worst = 0;
  for (int r = 0; r < 2; r++) CHECK_OK(hearth_sim_reset(e[r], 7, 0, 0, &err), &err);
  double E0 = hearth_thermo_energy(hearth_sim_thermal_net(e[0], 0));
  for (int t = 0; t < 300; t++) {
    double a[7], b[7];
    hearth_sim_expert_action(e[0], a);
    hearth_sim_expert_action(e[1], b);
    CHECK(memcmp(a, b, sizeof a) == 0); /* heat does not move the physics */
    CHECK_OK(hearth_sim_step(e[0], a, &err), &err);
    CHECK_OK(hearth_sim_step(e[1], b, &err), &err);
    const hearth_thermo_net *n = hearth_sim_thermal_net(e[0], 0);
    for (size_t c = 0; c < n->n_contacts; c++) touched[n->contact[c].region]++;
    double dE = hearth_thermo_energy(n) - E0 - hearth_sim_thermal_heat_in(e[0], 0);
    if (fabs(dE) > worst) worst = fabs(dE);
    if (hearth_sim_success(e[0])) break;
  }
  CHECK_MSG(worst <= 1e-9 * E0, "energy bookkeeping with contacts off by %.3g J", worst);
  const hearth_thermo_net *f = hearth_sim_thermal_net(e[0], 0),
                          *z = hearth_sim_thermal_net(e[1], 0);
  size_t rc = 0, ru = SIZE_MAX;
  for (size_t i = 0; i < f->n; i++)
    if (touched[i] > touched[rc]) rc = i;
  for (size_t i = 0; i < f->n; i++)
    if (!touched[i] && ru == SIZE_MAX) ru = i;
  CHECK_MSG(touched[rc] > 0 && ru != SIZE_MAX, "finger contacts: most %d steps, untouched %zu",
            touched[rc], ru);
  if (touched[rc] > 0 && ru != SIZE_MAX) {
    double dc = z->region[rc].T - f->region[rc].T, du = z->region[ru].T - f->region[ru].T;
    printf("finger: region %s touched %d steps, %.3f degC below its twin; untouched %s %.3f\n",
           f->region[rc].name, touched[rc], dc, f->region[ru].name, du);
    CHECK_MSG(dc > 0 && dc > du, "touched %.4f untouched %.4f", dc, du);
  }
  CHECK(hearth_sim_thermal_heat_in(e[0], 0) < hearth_sim_thermal_heat_in(e[1], 0));
  hearth_sim_env_free(e[0]);
  hearth_sim_env_free(e[1]);
}

/* a neutral distractor (object 2) set on top of the hot cup (object 0),
 * no table or finger links: every step links the two networks; each
 * object's energy change is the heat the library booked from its air plus
 * what it got through the links, the links' heat sums to zero, the cup
 * ends cooler and the distractor warmer than their twins of a run without
 * object links; at a step of 1e4 s no temperature leaves the range of the
 * start temperatures and the air */
static void check_objects(const char *root) {
  hearth_err err = {0};
  hearth_sim_env *e[2] = {make_env_o(root, 0, 0, HEARTH_SIM_H_CONTACT, 60.0, 16, "none"),
                          make_env_o(root, 0, 0, 0, 60.0, 16, "none")};
  if (!e[0] || !e[1]) return;
  for (int r = 0; r < 2; r++) {
    CHECK_OK(hearth_sim_reset(e[r], 7, 0, 0, &err), &err);
    double p[3];
    sim_object_pos(e[r], 0, p);
    p[2] += e[r]->assets[0].size[2] + 0.001;
    sim_place_object(e[r], 2, p);
  }
  double E0[SIM_NOBJ], worst = 0, worst_sum = 0, Tlo = HEARTH_SIM_THERMAL_ROOM, Thi = Tlo;
  for (int k = 0; k < SIM_NOBJ; k++) {
    const hearth_thermo_net *n = hearth_sim_thermal_net(e[0], k);
    E0[k] = hearth_thermo_energy(n);
    for (size_t i = 0; i < n->n; i++) {
      if (n->region[i].T < Tlo) Tlo = n->region[i].T;
      if (n->region[i].T > Thi) Thi = n->region[i].T;
    }
  }
  int linked = 0, steps = 220;
  double zero[7] = {0, 0, 0, 0, 0, 0, -1}, overshoot = 0;
  double q0 = 0, q2 = 0, c0 = 0, t0 = 0, c2 = 0, t2 = 0;
  for (int t = 0; t < steps; t++) {
    if (t == 200) {
      /* 10 thermal minutes: the exchange so far; then steps of dt = 1e4 s */
      q0 = hearth_sim_thermal_heat_exchanged(e[0], 0),
      q2 = hearth_sim_thermal_heat_exchanged(e[0], 2);
      c0 = hearth_thermo_mean_temperature(hearth_sim_thermal_net(e[0], 0)),
      t0 = hearth_thermo_mean_temperature(hearth_sim_thermal_net(e[1], 0));
      c2 = hearth_thermo_mean_temperature(hearth_sim_thermal_net(e[0], 2)),
      t2 = hearth_thermo_mean_temperature(hearth_sim_thermal_net(e[1], 2));
      e[0]->thermal_speedup = e[1]->thermal_speedup = 2e5;
    }
    for (int r = 0; r < 2; r++) CHECK_OK(hearth_sim_step(e[r], zero, &err), &err);
    hearth_thermo_link lk[8];
    size_t nl = hearth_sim_thermal_links(e[0], lk, 8);
    for (size_t l = 0; l < nl && l < 8; l++)
      CHECK_MSG(lk[l].a == 0 && lk[l].b == 2 && lk[l].G > 0, "step %d link %zu: %zu-%zu G %g", t, l,
                lk[l].a, lk[l].b, lk[l].G);
    linked += nl > 0;
    CHECK(hearth_sim_thermal_links(e[1], NULL, 0) == 0);
    double sum = 0, scale = 0;
    for (int k = 0; k < SIM_NOBJ; k++) {
      const hearth_thermo_net *n = hearth_sim_thermal_net(e[0], k);
      double dE = hearth_thermo_energy(n) - E0[k] - hearth_sim_thermal_heat_in(e[0], k) -
                  hearth_sim_thermal_heat_exchanged(e[0], k);
      if (fabs(dE) > worst) worst = fabs(dE);
      sum += hearth_sim_thermal_heat_exchanged(e[0], k);
      scale += fabs(hearth_sim_thermal_heat_exchanged(e[0], k));
      for (size_t i = 0; i < n->n; i++) {
        double o = fmax(n->region[i].T - Thi, Tlo - n->region[i].T);
        if (o > overshoot) overshoot = o;
      }
    }
    if (fabs(sum) > worst_sum) worst_sum = fabs(sum);
    CHECK_MSG(fabs(sum) <= 1e-12 * scale + 1e-12, "step %d: links' heat sums to %.3g J", t, sum);
  }
  CHECK_MSG(linked >= steps * 9 / 10, "the stacked objects were linked in %d of %d steps", linked,
            steps);
  CHECK_MSG(worst <= 1e-9 * fabs(E0[0]), "energy bookkeeping with object links off by %.3g J",
            worst);
  CHECK_MSG(overshoot <= 1e-9, "a temperature left [%.2f, %.2f] by %.3g degC", Tlo, Thi, overshoot);
  printf(
      "objects: linked %d/%d steps; after 600 s the cup gave %.1f J, the distractor got %.1f J; "
      "cup %.3f vs twin %.3f, distractor %.3f vs twin %.3f degC; bookkeeping %.2g J, links' sum "
      "%.2g J\n",
      linked, steps, -q0, q2, c0, t0, c2, t2, worst, worst_sum);
  CHECK_MSG(q0 < 0 && q2 > 0, "link heat: cup %.3f J, distractor %.3f J", q0, q2);
  CHECK_MSG(c0 < t0 && c2 > t2, "cup %.4f twin %.4f; distractor %.4f twin %.4f", c0, t0, c2, t2);
  hearth_sim_env_free(e[0]);
  hearth_sim_env_free(e[1]);
}

static unsigned char *slurp(const char *path, size_t *n) {
  FILE *fp = fopen(path, "rb");
  if (!fp) return NULL;
  fseek(fp, 0, SEEK_END);
  long len = ftell(fp);
  fseek(fp, 0, SEEK_SET);
  unsigned char *b = malloc(len > 0 ? (size_t)len : 1);
  *n = b ? fread(b, 1, (size_t)len, fp) : 0;
  fclose(fp);
  return b;
}

static void collect(const char *root, const char *out, int mode, int set) {
  hearth_sim_collect_opts o;
  hearth_sim_collect_opts_default(&o);
  o.task = HEARTH_SIM_H1;
  o.release_root = root;
  o.layouts = 1;
  o.image_size = 32;
  o.quiet = 1;
  o.out_path = out;
  if (set) o.thermal = mode;
  hearth_err err = {0};
  CHECK_OK(hearth_sim_collect(&o, NULL, &err), &err);
}

/* static: the bytes of a collection without the option; dynamic: the same
 * actions and states plus obs/thermal_state (T, R) with its columns */
static void check_files(const char *root, const char *dir) {
  char a[1200], b[1200], c[1200];
  snprintf(a, sizeof a, "%s/plain.hdf5", dir);
  snprintf(b, sizeof b, "%s/static.hdf5", dir);
  snprintf(c, sizeof c, "%s/dynamic.hdf5", dir);
  collect(root, a, 0, 0);
  collect(root, b, HEARTH_SIM_THERMAL_STATIC, 1);
  collect(root, c, HEARTH_SIM_THERMAL_DYNAMIC, 1);
  size_t na = 0, nb = 0;
  unsigned char *pa = slurp(a, &na), *pb = slurp(b, &nb);
  CHECK(pa && pb && na == nb && na > 0 && memcmp(pa, pb, na) == 0);
  free(pa), free(pb);
  hid_t fs = H5Fopen(a, H5F_ACC_RDONLY, H5P_DEFAULT), fd = H5Fopen(c, H5F_ACC_RDONLY, H5P_DEFAULT);
  CHECK(fs >= 0 && fd >= 0);
  if (fs < 0 || fd < 0) return;
  CHECK(H5Lexists(fs, "data/demo_0/obs/thermal_state", H5P_DEFAULT) == 0);
  hid_t ds = H5Dopen2(fd, "data/demo_0/obs/thermal_state", H5P_DEFAULT);
  CHECK(ds >= 0);
  hid_t sa = H5Dopen2(fs, "data/demo_0/actions", H5P_DEFAULT),
        da = H5Dopen2(fd, "data/demo_0/actions", H5P_DEFAULT);
  hsize_t dims[2] = {0}, ad[2] = {0};
  if (ds >= 0) {
    hid_t sp = H5Dget_space(ds);
    CHECK(H5Sget_simple_extent_ndims(sp) == 2);
    H5Sget_simple_extent_dims(sp, dims, NULL);
    H5Sclose(sp);
    hid_t t = H5Dget_type(ds);
    CHECK(H5Tget_class(t) == H5T_FLOAT && H5Tget_size(t) == 4);
    H5Tclose(t);
    CHECK(H5Aexists(ds, "region_names") > 0 && H5Aexists(ds, "heat_capacity") > 0);
  }
  hid_t sp = H5Dget_space(sa);
  H5Sget_simple_extent_dims(sp, ad, NULL);
  H5Sclose(sp);
  CHECK_MSG(dims[0] == ad[0] && dims[1] >= 8, "thermal_state (%llu, %llu), actions T %llu",
            (unsigned long long)dims[0], (unsigned long long)dims[1], (unsigned long long)ad[0]);
  double *x = malloc(ad[0] * 7 * sizeof(double)), *y = malloc(ad[0] * 7 * sizeof(double));
  float *th = malloc((dims[0] ? dims[0] : 1) * (dims[1] ? dims[1] : 1) * sizeof(float));
  H5Dread(sa, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x);
  H5Dread(da, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, y);
  CHECK(memcmp(x, y, ad[0] * 7 * sizeof(double)) == 0);
  if (ds >= 0 && dims[0] > 1) {
    H5Dread(ds, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, th);
    /* the scene's thermal energy (sum C T over the columns) falls: the hot
     * cup loses heat to the room */
    double *C = malloc(dims[1] * sizeof(double)), E[2] = {0, 0};
    hid_t at = H5Aopen(ds, "heat_capacity", H5P_DEFAULT);
    CHECK(at >= 0 && H5Aread(at, H5T_NATIVE_DOUBLE, C) >= 0);
    if (at >= 0) H5Aclose(at);
    for (size_t j = 0; j < dims[1]; j++)
      E[0] += C[j] * th[j], E[1] += C[j] * th[(dims[0] - 1) * dims[1] + j];
    CHECK_MSG(E[1] < E[0], "stored energy %.3f -> %.3f J", E[0], E[1]);
    free(C);
  }
  free(x), free(y), free(th);
  H5Dclose(sa), H5Dclose(da);
  if (ds >= 0) H5Dclose(ds);
  H5Fclose(fs), H5Fclose(fd);
}

int main(void) {
  const char *dir = test_tmpdir("sim_thermal");
  char dirbuf[1100];
  snprintf(dirbuf, sizeof dirbuf, "%s", dir);
  const char *root = test_sim_release(dirbuf);
  check_alone(root, dirbuf);
  check_finger(root);
  check_objects(root);
  check_gl(root);
  check_files(root, dirbuf);
  return g_test_failures ? 1 : 0;
}
