/* Scene renders of an expert episode: the front RGB and thermal views at
 * three moments (the start, the grasp, the end) of one layout of a task,
 * written as OUT/<task>_<moment>_{rgb,thermal}.png (top row first), with
 * the candidates' mean temperatures at each moment on stdout.
 *
 *   bench_sim_moments --task H5 --out DIR [--size N] [--layout L] [--instruction I]
 *
 * The assets come from a small virtual-rig release made under DIR/release
 * (as `hearth sim render` makes without --release). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/hearth.h"
#include "hearth/sim.h"
#include "hearth/synth.h"
#include "hearth/thermo.h"

static int write_view(const char *path, const uint8_t *img, int w, int h) {
  hearth_image im;
  hearth_err err = {0};
  if (hearth_image_alloc(&im, (size_t)w, (size_t)h, 3, HEARTH_PIX_U8, &err)) return 1;
  for (int y = 0; y < h; y++)
    memcpy((uint8_t *)im.data + (size_t)y * w * 3, img + (size_t)(h - 1 - y) * w * 3,
           (size_t)w * 3);
  int rc = hearth_png_write(path, &im, &err) != HEARTH_OK;
  if (rc) fprintf(stderr, "%s\n", err.msg);
  hearth_image_free(&im);
  return rc;
}

static double net_mean(const hearth_thermo_net *n) {
  double cT = 0, c = 0;
  for (size_t i = 0; n && i < n->n; i++) cT += n->region[i].C * n->region[i].T, c += n->region[i].C;
  return c > 0 ? cT / c : 0;
}

static int shoot(hearth_sim_env *e, const char *out, const char *task, const char *moment) {
  hearth_sim_obs ob;
  hearth_err err = {0};
  if (hearth_sim_observe(e, &ob, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    return 1;
  }
  char p[4400];
  snprintf(p, sizeof p, "%s/%s_%s_rgb.png", out, task, moment);
  int rc = write_view(p, ob.agentview_rgb, ob.width, ob.height);
  snprintf(p, sizeof p, "%s/%s_%s_thermal.png", out, task, moment);
  rc |= write_view(p, ob.agentview_thermal, ob.width, ob.height);
  if (hearth_sim_thermal_net(e, 0))
    printf("%s %-6s step %3d: candidate 1 %.1f degC, candidate 2 %.1f degC\n", task, moment,
           hearth_sim_steps(e), net_mean(hearth_sim_thermal_net(e, 0)),
           net_mean(hearth_sim_thermal_net(e, 1)));
  else /* static temperatures (H1-H4 by default) */
    printf("%s %-6s step %3d\n", task, moment, hearth_sim_steps(e));
  return rc;
}

int main(int argc, char **argv) {
  const char *out = NULL, *tname = "H5";
  int size = 256, instruction = 0;
  unsigned long long layout = 0;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--task") && i + 1 < argc) tname = argv[++i];
    else if (!strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
    else if (!strcmp(argv[i], "--size") && i + 1 < argc) size = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--layout") && i + 1 < argc) layout = strtoull(argv[++i], NULL, 10);
    else if (!strcmp(argv[i], "--instruction") && i + 1 < argc) instruction = atoi(argv[++i]);
    else out = NULL, i = argc;
  }
  hearth_sim_task task = hearth_sim_task_parse(tname);
  if (!out || !task || size < 16 || instruction < 0 || instruction > 1) {
    fprintf(stderr,
            "usage: bench_sim_moments --task H5 --out DIR [--size N] [--layout L] "
            "[--instruction 0|1]\n");
    return 2;
  }
  hearth_err err = {0};
  char root[4200];
  snprintf(root, sizeof root, "%s/release", out);
  if (hearth_mkdirs(out, &err)) return fprintf(stderr, "%s\n", err.msg), 1;
  hearth_synth_opts so;
  hearth_synth_opts_sim_assets(&so);
  so.out_root = root;
  hearth_remove_tree(root, NULL);
  if (hearth_synth_release(&so, &err)) return fprintf(stderr, "%s\n", err.msg), 1;
  hearth_sim_opts o;
  hearth_sim_opts_default(&o);
  o.task = task;
  o.release_root = root;
  o.width = o.height = size;
  o.render_wrist = 0;
  hearth_sim_env *e = NULL;
  if (hearth_sim_env_new(&o, &e, &err) ||
      hearth_sim_reset(e, 1, (uint64_t)layout, instruction, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    hearth_sim_env_free(e);
    return 1;
  }
  int rc = shoot(e, out, tname, "start");
  int grasped = 0;
  for (int s = 0; s < 400 && !rc; s++) {
    double a[7];
    hearth_sim_expert_action(e, a);
    if (hearth_sim_step(e, a, &err)) {
      fprintf(stderr, "%s\n", err.msg);
      rc = 1;
      break;
    }
    /* the grasp: the first step the expert closes the hand and lifts (H4
     * lifts at a third of the speed: 0.33) */
    if (!grasped && a[6] > 0 && a[2] > 0.3) grasped = 1, rc |= shoot(e, out, tname, "grasp");
    if (hearth_sim_success(e) || hearth_sim_failure(e)) break;
  }
  if (!rc) rc = shoot(e, out, tname, "end");
  printf("%s: %s\n", tname,
         hearth_sim_success(e)   ? "success"
         : hearth_sim_failure(e) ? hearth_sim_failure(e)
                                 : "time limit");
  hearth_sim_env_free(e);
  return rc;
}
