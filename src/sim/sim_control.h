/* private: the arm's operational-space controller (sim_control.c) */
#ifndef HEARTH_SIM_CONTROL_H
#define HEARTH_SIM_CONTROL_H

typedef struct hearth_sim_env hearth_sim_env;

/* robosuite's OSC_POSE on the env's model and data after mj_step1: sets
 * d->ctrl of the seven arm motors (torques towards e->goal_pos, e->goal_R,
 * with gravity and bias compensation, clipped to the torque limits) and of
 * the two finger servos (from e->grip_cmd, -1 open .. +1 closed). Leaves
 * d->ctrl as it was when one of the matrices it inverts is near singular. */
void sim_osc(hearth_sim_env *e);

#endif
