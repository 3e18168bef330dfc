/* The scripted expert: a phase machine over privileged state (approach,
 * descend, close, lift, transport, lower, release, retreat) that turns the
 * target's pose into delta actions. */
#include <math.h>

#include "hearth/geom.h"
#include "sim/sim_env.h"
#include "sim/sim_robot.h"

static double clip1(double x) { return x < -1 ? -1 : x > 1 ? 1 : x; }

void hearth_sim_expert_action(hearth_sim_env *e, double act[7]) {
  const mjData *d = e->d;
  int k = e->target;
  const sim_asset *a = &e->assets[k];
  const double *q = d->qpos + e->obj_qadr[k];
  const double *x = d->site_xpos + 3 * e->site_grip, *R = d->site_xmat + 9 * e->site_grip;
  double h = a->size[2];
  /* H4: the grasp is at a handle of the pot (the cool one unless a test
   * asks for the other), and the carried pot's origin is offset from the
   * hand by the handle's reach */
  const int handles = sim_task_get(e->task)->handles;
  double grasp[3] = {q[0], q[1], q[2]}, off[2] = {0, 0};
  if (handles) {
    int lug = e->expert_lug >= 0 ? e->expert_lug : 1 - e->hd.hot;
    sim_handles_grasp_point(e, lug, grasp);
    if (e->phase >= 3) off[0] = x[0] - q[0], off[1] = x[1] - q[1];
  }
  /* grasp at half height, but keep the pads (centred on the grip site,
   * 22 mm half height) 2 mm clear of the table: pressing them into the
   * table stalls the descent and makes the closing pads ride up over thin
   * objects. Tall objects: at most 6 cm up (a firm hold low on the body) */
  double gz = handles ? grasp[2] - q[2] : fmin(fmax(0.5 * h, SIM_PAD_HALF_Z + 0.002), 0.06);
  if (handles && e->phase >= 3) gz = x[2] - q[2];
  double lift_z = HEARTH_SIM_TABLE_Z + 0.16 + gz;
  double tgt[3];
  double grip = -1;
  int next = 0;
  double tol = 0.01;
  switch (e->phase) {
    case 0: { /* above the target, high enough that the open pads pass over
             * every other object (the kettle stands 20 cm tall) */
      double tallest = 0;
      for (int j = 0; j < SIM_NOBJ; j++)
        if (j != k) tallest = fmax(tallest, e->assets[j].size[2]);
      tgt[0] = grasp[0], tgt[1] = grasp[1];
      tgt[2] = fmax(fmax(q[2] + h + 0.08, lift_z - 0.04),
                    HEARTH_SIM_TABLE_Z + tallest + SIM_PAD_HALF_Z + 0.04);
      tol = 0.015;
      next = 1;
      break;
    }
    case 1: /* down to the grasp height */
      tgt[0] = grasp[0], tgt[1] = grasp[1], tgt[2] = q[2] + gz;
      tol = 0.006;
      next = 1;
      break;
    case 2: /* close, holding the grasp height: following the hand as the
           * closing pads push it up would let them ride over thin objects */
      tgt[0] = x[0], tgt[1] = x[1], tgt[2] = q[2] + gz;
      grip = 1;
      next = e->phase_steps >= 8;
      break;
    case 3: /* lift */
      tgt[0] = x[0], tgt[1] = x[1], tgt[2] = lift_z;
      grip = 1;
      tol = 0.02;
      next = 1;
      break;
    case 4: /* transport above the mat */
      tgt[0] = sim_mat_centre[0] + off[0], tgt[1] = sim_mat_centre[1] + off[1], tgt[2] = lift_z;
      grip = 1;
      tol = 0.015;
      next = 1;
      break;
    case 5: /* lower until the object is just above the mat */
      tgt[0] = sim_mat_centre[0] + off[0], tgt[1] = sim_mat_centre[1] + off[1],
      tgt[2] = HEARTH_SIM_TABLE_Z + 0.002 + gz + (handles ? 0.004 : 0.012);
      grip = 1;
      tol = 0.008;
      next = 1;
      break;
    case 6: /* release */
      tgt[0] = x[0], tgt[1] = x[1], tgt[2] = x[2];
      grip = -1;
      next = e->phase_steps >= 6;
      break;
    default: /* retreat upwards */
      tgt[0] = x[0], tgt[1] = x[1], tgt[2] = lift_z;
      grip = -1;
      break;
  }
  double err3[3] = {tgt[0] - x[0], tgt[1] - x[1], tgt[2] - x[2]};
  double dist = hearth_norm3(err3);
  for (int i = 0; i < 3; i++) act[i] = clip1(err3[i] / 0.05 * 1.5);
  /* H4: the pot hangs from one handle: carry it at a third of the speed
   * (1.7 cm per step at most) so it swings less */
  if (handles && e->phase >= 3 && e->phase <= 5)
    for (int i = 0; i < 3; i++) act[i] = fmax(-0.33, fmin(0.33, act[i]));
  /* keep the start orientation: axis-angle of R0 R^T */
  double Rt[9], dR[9], w[3];
  hearth_mat3_transpose(R, Rt);
  hearth_mat3_mul(e->R0, Rt, dR);
  hearth_matrix_to_rotvec(dR, w);
  for (int i = 0; i < 3; i++) act[3 + i] = clip1(w[i] / 0.5);
  if (handles && e->phase >= 3) {
    /* the held pot tilts about the pinch: turn the hand, and the pot with
     * it, by half the rotation that levels the pot each step (the pot's z
     * axis onto the world's); hold the hand's orientation once released */
    const double *Rp = d->xmat + 9 * e->obj_body[0];
    double zp[3] = {Rp[2], Rp[5], Rp[8]}, ez[3] = {0, 0, 1}, ax[3];
    hearth_cross3(zp, ez, ax);
    double sn = hearth_norm3(ax), ang = atan2(sn, zp[2]);
    for (int i = 0; i < 3; i++)
      act[3 + i] = e->phase <= 5 && sn > 1e-9 ? clip1(0.5 * ang * ax[i] / sn / 0.5) : 0.0;
  }
  act[6] = grip;
  e->phase_steps++;
  int done = 0;
  if (e->phase == 2 || e->phase == 6) done = next;
  else if (e->phase < 7) done = dist < tol || (e->phase_steps > 60);
  if (done && e->phase < 7) e->phase++, e->phase_steps = 0;
}
