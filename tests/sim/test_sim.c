/* the sim tasks end to end on a tiny virtual-rig release: the expert
 * succeeds, candidates look identical in RGB but differ in thermal, and the
 * collected HDF5 file has LIBERO's keys and shapes */
#include <hdf5.h>
#include <stdint.h>

#include "hearth/hearth.h"
#include "hearth/sim.h"
#include "test_util.h"

static const char *make_release(const char *dir) {
  static char root[1200];
  snprintf(root, sizeof root, "%s/release", dir);
  hearth_synth_opts so;
  hearth_synth_opts_default(&so);
  so.out_root = root;
  const char *cats[] = {"cup", "canned_drink", "electric_kettle", "eraser", "orange", "smartphone", "sponge"};
  so.n_categories = 7;
  for (int i = 0; i < 7; i++) so.categories[i] = cats[i];
  so.n_states = 3;
  so.states[0] = "neutral", so.states[1] = "hot", so.states[2] = "iced";
  so.n_views = 6;
  so.triangles = 2000;
  so.texture_size = 128;
  so.map_resolution = 64;
  so.calibration = 0;
  so.quiet = 1;
  hearth_err err = {0};
  CHECK_OK(hearth_synth_release(&so, &err), &err);
  return root;
}

/* mean colour of a box */
static void box_mean(const uint8_t *img, int w, const int b[4], double m[3]) {
  double n = 0;
  m[0] = m[1] = m[2] = 0;
  for (int y = b[1]; y <= b[3]; y++)
    for (int x = b[0]; x <= b[2]; x++) {
      for (int c = 0; c < 3; c++) m[c] += img[3 * (y * w + x) + c];
      n++;
    }
  for (int c = 0; c < 3; c++) m[c] /= n;
}

static void check_task(const char *root, hearth_sim_task task, int check_crops) {
  hearth_err err = {0};
  hearth_sim_opts o;
  hearth_sim_opts_default(&o);
  o.task = task;
  o.release_root = root;
  o.width = o.height = 64;
  hearth_sim_env *e = NULL;
  CHECK_OK(hearth_sim_env_new(&o, &e, &err), &err);
  if (!e) return;
  for (int ins = 0; ins < 2; ins++) {
    CHECK_OK(hearth_sim_reset(e, 7, 0, ins, &err), &err);
    if (ins == 0 && check_crops) {
      hearth_sim_obs ob;
      int boxes[2][4];
      CHECK_OK(hearth_sim_observe(e, &ob, &err), &err);
      CHECK_OK(hearth_sim_candidate_boxes(e, boxes, &err), &err);
      /* a common box size so the crops cover the same object area */
      int bw = boxes[0][2] - boxes[0][0], bh = boxes[0][3] - boxes[0][1];
      int b1[4] = {boxes[1][0], boxes[1][1], boxes[1][0] + bw, boxes[1][1] + bh};
      if (b1[2] >= ob.width) b1[2] = ob.width - 1;
      if (b1[3] >= ob.height) b1[3] = ob.height - 1;
      double r0[3], r1[3], t0[3], t1[3];
      box_mean(ob.agentview_rgb, ob.width, boxes[0], r0);
      box_mean(ob.agentview_rgb, ob.width, b1, r1);
      box_mean(ob.agentview_thermal, ob.width, boxes[0], t0);
      box_mean(ob.agentview_thermal, ob.width, b1, t1);
      double drgb = 0, dth = 0;
      for (int c = 0; c < 3; c++) drgb += fabs(r0[c] - r1[c]), dth += fabs(t0[c] - t1[c]);
      CHECK_MSG(drgb < 20, "%s: RGB crops of the candidates differ by %.1f", hearth_sim_task_name(task), drgb);
      CHECK_MSG(dth > 60, "%s: thermal crops of the candidates differ by only %.1f", hearth_sim_task_name(task), dth);
      double tv = 0, ov = 0;
      CHECK_OK(hearth_sim_visibility(e, &tv, &ov, &err), &err);
      CHECK(tv > 0.5 && ov > 0.5);
    }
    int ok = 0;
    for (int t = 0; t < hearth_sim_max_steps(e) && !ok; t++) {
      double a[7];
      hearth_sim_expert_action(e, a);
      CHECK_OK(hearth_sim_step(e, a, &err), &err);
      ok = hearth_sim_success(e);
    }
    CHECK_MSG(ok, "%s instruction %d: expert failed", hearth_sim_task_name(task), ins);
  }
  /* bad input */
  double bad[7] = {0, 0, NAN, 0, 0, 0, 0};
  CHECK(hearth_sim_step(e, bad, &err) == HEARTH_E_RANGE);
  CHECK(hearth_sim_reset(e, 1, 0, 2, &err) == HEARTH_E_ARG);
  hearth_sim_env_free(e);
}

static void check_hdf5(const char *root, const char *dir) {
  char path[1200];
  snprintf(path, sizeof path, "%s/h1.hdf5", dir);
  hearth_sim_collect_opts o;
  hearth_sim_collect_opts_default(&o);
  o.task = HEARTH_SIM_H1;
  o.release_root = root;
  o.layouts = 1;
  o.image_size = 32;
  o.quiet = 1;
  o.out_path = path;
  hearth_err err = {0};
  hearth_sim_collect_stats s;
  CHECK_OK(hearth_sim_collect(&o, &s, &err), &err);
  CHECK(s.demos == 2);
  hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  CHECK(f >= 0);
  if (f < 0) return;
  hid_t d = H5Dopen2(f, "data/demo_0/obs/agentview_thermal", H5P_DEFAULT);
  CHECK(d >= 0);
  if (d >= 0) {
    hid_t sp = H5Dget_space(d);
    hsize_t dims[4] = {0};
    CHECK(H5Sget_simple_extent_ndims(sp) == 4);
    H5Sget_simple_extent_dims(sp, dims, NULL);
    CHECK(dims[1] == 32 && dims[2] == 32 && dims[3] == 3 && dims[0] > 10);
    H5Sclose(sp);
    H5Dclose(d);
  }
  const char *keys[] = {"data/demo_0/actions", "data/demo_0/states", "data/demo_0/rewards",
                        "data/demo_0/dones", "data/demo_1/obs/agentview_rgb",
                        "data/demo_1/obs/eye_in_hand_rgb", "data/demo_1/obs/joint_states",
                        "data/demo_1/obs/gripper_states", "data/demo_1/obs/ee_states",
                        "data/demo_1/obs/ee_pos", "data/demo_1/obs/ee_ori"};
  for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
    CHECK_MSG(H5Lexists(f, keys[i], H5P_DEFAULT) > 0 || 0, "%s missing", keys[i]);
  CHECK(H5Aexists_by_name(f, "data", "problem_info", H5P_DEFAULT) > 0);
  CHECK(H5Aexists_by_name(f, "data", "num_demos", H5P_DEFAULT) > 0);
  CHECK(H5Aexists_by_name(f, "data/demo_0", "num_samples", H5P_DEFAULT) > 0);
  H5Fclose(f);
}

int main(void) {
  const char *dir = test_tmpdir("sim_tasks");
  char dirbuf[1100];
  snprintf(dirbuf, sizeof dirbuf, "%s", dir);
  const char *root = make_release(dirbuf);
  check_task(root, HEARTH_SIM_H1, 1);
  check_task(root, HEARTH_SIM_H2, 1);
  check_task(root, HEARTH_SIM_H3, 0); /* category task: no identical-crop check */
  check_hdf5(root, dirbuf);
  return g_test_failures ? 1 : 0;
}
