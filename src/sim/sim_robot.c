/* The Panda arm: modified DH kinematics, link masses, joint and torque
 * limits, the hand with its wrist camera and two slide fingers, written as
 * the MJCF body tree and actuators of the scene. */
#include <math.h>

#include "hearth/geom.h"
#include "sim/sim_mjcf.h"
#include "sim/sim_robot.h"

/* modified DH rows (a_{i-1}, d_i, alpha_{i-1}) of the Panda, then the flange */
static const double k_dh[8][3] = {{0, 0.333, 0},
                                  {0, 0, -M_PI / 2},
                                  {0, 0.316, M_PI / 2},
                                  {0.0825, 0, M_PI / 2},
                                  {-0.0825, 0.384, -M_PI / 2},
                                  {0, 0, M_PI / 2},
                                  {0.088, 0, M_PI / 2},
                                  {0, 0.107, 0}};
static const double k_link_mass[7] = {4.0, 4.0, 3.0, 3.0, 2.5, 1.5, 0.6};
static const double k_jlo[7] = {-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973};
static const double k_jhi[7] = {2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973};
/* behind the table, facing +x */
static const double k_robot_base[3] = {-0.66, 0.0, 0.912};

const double sim_robot_q_start[7] = {0, -0.161, 0, -2.445, 0, 2.227, 0.78539816339744831};
const double sim_robot_tau_max[7] = {87, 87, 87, 87, 12, 12, 12};

/* the frame of DH row `row` in its parent's */
static void dh_child(int row, double pos[3], double quat[4]) {
  double a = k_dh[row][0], d = k_dh[row][1], al = k_dh[row][2];
  pos[0] = a, pos[1] = -sin(al) * d, pos[2] = cos(al) * d;
  quat[0] = cos(al / 2), quat[1] = sin(al / 2), quat[2] = 0, quat[3] = 0;
}

void sim_robot_emit_bodies(hearth_strbuf *b) {
  const char *rob = "contype=\"2\" conaffinity=\"1\" group=\"1\"";
  hearth_strbuf_printf(b, "<body name=\"base\" pos=\"%s %s %s\">\n", sim_num(k_robot_base[0]).s,
                       sim_num(k_robot_base[1]).s, sim_num(k_robot_base[2]).s);
  hearth_strbuf_printf(
      b,
      "<geom type=\"cylinder\" size=\"0.09 0.45\" pos=\"0 0 -0.45\" material=\"robot_dark\" %s/>\n",
      rob);
  for (int i = 0; i < 7; i++) {
    double p[3], q[4];
    dh_child(i, p, q);
    hearth_strbuf_printf(b, "<body name=\"link%d\" pos=\"%s %s %s\" quat=\"%s %s %s %s\">\n", i + 1,
                         sim_num(p[0]).s, sim_num(p[1]).s, sim_num(p[2]).s, sim_num(q[0]).s,
                         sim_num(q[1]).s, sim_num(q[2]).s, sim_num(q[3]).s);
    hearth_strbuf_printf(b,
                         "<inertial pos=\"0 0 0\" mass=\"%s\" diaginertia=\"0.02 0.02 0.01\"/>\n",
                         sim_num(k_link_mass[i]).s);
    hearth_strbuf_printf(
        b,
        "<joint name=\"j%d\" axis=\"0 0 1\" range=\"%s %s\" damping=\"0.1\" armature=\"0.1\"/>\n",
        i + 1, sim_num(k_jlo[i]).s, sim_num(k_jhi[i]).s);
    /* a joint housing along the axis, and a capsule to the next joint */
    double rj = i < 4 ? 0.06 : 0.05;
    hearth_strbuf_printf(b,
                         "<geom type=\"cylinder\" size=\"%s 0.055\" material=\"robot_white\" %s/>\n",
                         sim_num(rj).s, rob);
    double c[3], cq[4];
    dh_child(i + 1, c, cq);
    if (hearth_norm3(c) > 1e-6)
      hearth_strbuf_printf(
          b,
          "<geom type=\"capsule\" fromto=\"0 0 0 %s %s %s\" size=\"%s\" material=\"robot_white\" %s/>\n",
          sim_num(c[0]).s, sim_num(c[1]).s, sim_num(c[2]).s, sim_num(rj * 0.9).s, rob);
  }
  /* flange and hand: fingers close along the hand's y axis */
  double p[3], q[4];
  dh_child(7, p, q);
  hearth_strbuf_printf(b, "<body name=\"hand\" pos=\"%s %s %s\" quat=\"%s 0 0 %s\">\n",
                       sim_num(p[0]).s, sim_num(p[1]).s, sim_num(p[2]).s, sim_num(cos(-M_PI / 8)).s,
                       sim_num(sin(-M_PI / 8)).s);
  hearth_strbuf_printf(
      b, "<inertial pos=\"0 0 0.03\" mass=\"0.7\" diaginertia=\"0.003 0.002 0.002\"/>\n");
  hearth_strbuf_printf(
      b,
      "<geom type=\"box\" size=\"0.025 0.09 0.025\" pos=\"0 0 0.035\" material=\"robot_white\" %s/>\n",
      rob);
  hearth_strbuf_printf(
      b,
      "<geom type=\"cylinder\" size=\"0.04 0.01\" pos=\"0 0 0.005\" material=\"robot_dark\" %s/>\n",
      rob);
  hearth_strbuf_printf(
      b, "<camera name=\"eye_in_hand\" pos=\"0.07 0 0.02\" quat=\"0 1 0 0\" fovy=\"75\"/>\n");
  hearth_strbuf_printf(b,
                       "<site name=\"grip\" pos=\"0 0 0.1034\" size=\"0.005\" rgba=\"1 0 0 0\"/>\n");
  for (int s = 0; s < 2; s++) {
    double sign = s == 0 ? 1 : -1;
    hearth_strbuf_printf(b, "<body name=\"finger_%s\" pos=\"0 0 0.0584\">\n",
                         s == 0 ? "left" : "right");
    hearth_strbuf_printf(
        b, "<inertial pos=\"0 0 0.03\" mass=\"0.03\" diaginertia=\"1e-5 1e-5 1e-5\"/>\n");
    /* damping caps the closing speed near 0.2 m/s (under 0.4 mm per
     * physics step at the 15 N force limit) so the pads cannot tunnel
     * through thin objects such as a phone; 15 N holds the heaviest
     * candidate (0.3 kg) with a wide margin and keeps the pads from sinking
     * into light objects' soft contacts */
    hearth_strbuf_printf(
        b,
        "<joint name=\"finger_%d\" type=\"slide\" axis=\"0 %s 0\" range=\"0 0.04\" damping=\"80\" armature=\"0.01\"/>\n",
        s + 1, sim_num(sign).s);
    hearth_strbuf_printf(
        b,
        "<geom name=\"pad_%d\" type=\"box\" size=\"0.011 0.006 %s\" pos=\"0 %s 0.045\" "
        "friction=\"2 0.02 0.001\" condim=\"4\" solref=\"0.005 1\" solimp=\"0.95 0.99 0.001\" material=\"robot_dark\" %s/>\n",
        s + 1, sim_num(SIM_PAD_HALF_Z).s, sim_num(sign * 0.006).s, rob);
    hearth_strbuf_printf(b, "</body>\n");
  }
  hearth_strbuf_printf(b, "</body>\n");
  for (int i = 0; i < 7; i++) hearth_strbuf_printf(b, "</body>\n");
  hearth_strbuf_printf(b, "</body>\n");
}

void sim_robot_emit_actuators(hearth_strbuf *b) {
  hearth_strbuf_printf(b,
                       "<contact><exclude body1=\"hand\" body2=\"finger_left\"/>"
                       "<exclude body1=\"hand\" body2=\"finger_right\"/></contact>\n<actuator>\n");
  for (int i = 0; i < 7; i++)
    hearth_strbuf_printf(
        b, "<motor name=\"m%d\" joint=\"j%d\" ctrllimited=\"true\" ctrlrange=\"%s %s\"/>\n", i + 1,
        i + 1, sim_num(-sim_robot_tau_max[i]).s, sim_num(sim_robot_tau_max[i]).s);
  for (int s = 0; s < 2; s++)
    hearth_strbuf_printf(
        b,
        "<position name=\"g%d\" joint=\"finger_%d\" kp=\"800\" ctrllimited=\"true\" ctrlrange=\"0 0.04\" "
        "forcelimited=\"true\" forcerange=\"-15 15\"/>\n",
        s + 1, s + 1);
  hearth_strbuf_printf(b, "</actuator>\n");
}
