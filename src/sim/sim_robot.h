/* private: the Panda arm (sim_robot.c): its kinematic tree, masses, joint
 * and torque limits and hand, emitted as MJCF, and the numbers the
 * controller and the expert share with it */
#ifndef HEARTH_SIM_ROBOT_H
#define HEARTH_SIM_ROBOT_H

#include "hearth/core.h"

/* start posture of the seven arm joints, also the controller's null-space
 * target (rad) */
extern const double sim_robot_q_start[7];
/* torque limits of the arm joints (N m) */
extern const double sim_robot_tau_max[7];
/* half height of a finger pad (m), centred on the grip site */
#define SIM_PAD_HALF_Z 0.022
/* the pad's half width across the closing direction (hand x), m: the
 * 0.011 of its MJCF box (sim_robot.c) */
#define SIM_PAD_HALF_X 0.011

/* The arm's body tree inside <worldbody>: base, links 1-7 with joints
 * j1..j7, the hand (camera eye_in_hand, site grip) and the fingers
 * (joints finger_1, finger_2, geoms pad_1, pad_2). */
void sim_robot_emit_bodies(hearth_strbuf *b);
/* After </worldbody>: the hand-finger contact exclusions and the
 * <actuator> block (motors m1..m7, finger position servos g1, g2). */
void sim_robot_emit_actuators(hearth_strbuf *b);

#endif
