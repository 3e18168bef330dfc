/* The renderer alone: expert rollouts of a task (N layouts x 2
 * instructions, as `hearth sim collect` runs them) with the CPU time of
 * every hearth_sim_observe call (the three views) summed apart from the
 * physics, and one FNV-1a digest of every image byte, so that two builds
 * can be compared for speed and for identical images in one go.
 *
 *   bench_sim_render --release ROOT [--task H1] [--size 256] [--layouts 2]
 *                    [--renderer soft] [--ground-truth 0|1] [--steps 400]
 *
 * Prints "<task> <size> <renderer>: <steps> steps, observe <s> s CPU
 * (<ms> ms/step), rest <s> s CPU, images <digest>". */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hearth/hearth.h"
#include "hearth/sim.h"

static double cpu_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static uint64_t fnv(uint64_t h, const uint8_t *p, size_t n) {
  for (size_t i = 0; i < n; i++) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

int main(int argc, char **argv) {
  const char *root = NULL, *tname = "H1", *renderer = "soft";
  int size = 256, layouts = 2, gt = 1, max_steps = 400;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--release") && i + 1 < argc) root = argv[++i];
    else if (!strcmp(argv[i], "--task") && i + 1 < argc) tname = argv[++i];
    else if (!strcmp(argv[i], "--size") && i + 1 < argc) size = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--layouts") && i + 1 < argc) layouts = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--renderer") && i + 1 < argc) renderer = argv[++i];
    else if (!strcmp(argv[i], "--ground-truth") && i + 1 < argc) gt = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--steps") && i + 1 < argc) max_steps = atoi(argv[++i]);
    else root = NULL, i = argc;
  }
  hearth_sim_task task = hearth_sim_task_parse(tname);
  if (!root || !task || size < 16 || layouts < 1) {
    fprintf(stderr,
            "usage: bench_sim_render --release ROOT [--task H1] [--size 256] "
            "[--layouts 2] [--renderer soft] [--ground-truth 0|1] [--steps 400]\n");
    return 2;
  }
  hearth_err err = {0};
  hearth_sim_opts o;
  hearth_sim_opts_default(&o);
  o.task = task;
  o.release_root = root;
  o.use_ground_truth = gt;
  o.width = o.height = size;
  o.renderer = renderer;
  hearth_sim_env *e = NULL;
  if (hearth_sim_env_new(&o, &e, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    return 1;
  }
  uint64_t h = 1469598103934665603ull;
  double t_obs = 0, t0 = cpu_now();
  long steps = 0;
  int rc = 0;
  for (int l = 0; l < layouts && !rc; l++)
    for (int ins = 0; ins < 2 && !rc; ins++) {
      if (hearth_sim_reset(e, 1, (uint64_t)l, ins, &err)) {
        rc = 1;
        break;
      }
      for (int s = 0; s < max_steps; s++) {
        hearth_sim_obs ob;
        double a = cpu_now();
        if (hearth_sim_observe(e, &ob, &err)) {
          rc = 1;
          break;
        }
        t_obs += cpu_now() - a;
        size_t n = (size_t)ob.width * (size_t)ob.height * 3;
        if (ob.agentview_rgb) h = fnv(h, ob.agentview_rgb, n);
        if (ob.agentview_thermal) h = fnv(h, ob.agentview_thermal, n);
        if (ob.eye_in_hand_rgb) h = fnv(h, ob.eye_in_hand_rgb, n);
        double act[7];
        hearth_sim_expert_action(e, act);
        steps++;
        if (hearth_sim_step(e, act, &err)) {
          rc = 1;
          break;
        }
        if (hearth_sim_success(e) || hearth_sim_failure(e)) break;
      }
    }
  double total = cpu_now() - t0;
  if (rc) fprintf(stderr, "%s\n", err.msg);
  else
    printf(
        "%s %d %s: %ld steps, observe %.2f s CPU (%.2f ms/step), rest %.2f s CPU, images "
        "%016llx\n",
        tname, size, renderer, steps, t_obs, steps ? 1e3 * t_obs / (double)steps : 0.0,
        total - t_obs, (unsigned long long)h);
  hearth_sim_env_free(e);
  return rc;
}
