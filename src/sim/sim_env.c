/* the task environments: MJCF scene built in C, Panda arm with an
 * operational-space pose controller, layouts, success, scripted expert */
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hearth/geom.h"
#include "sim/sim_env.h"

/* ---- task table (paper, Table III) --------------------------------------- */
typedef struct task_obj {
  const char *category, *state, *noun;
} task_obj;
typedef struct task_def {
  const char *name, *scene;
  task_obj cand[2];   /* instruction i targets cand[i] */
  task_obj dist[2];
} task_def;

static const task_def k_tasks[3] = {
    {"H1", "study",
     {{"cup", "hot", "hot cup"}, {"cup", "neutral", "normal cup"}},
     {{"electric_kettle", "hot", "kettle"}, {"eraser", "neutral", "eraser"}}},
    {"H2", "kitchen",
     {{"canned_drink", "iced", "iced can"}, {"canned_drink", "neutral", "normal can"}},
     {{"orange", "iced", "orange"}, {"cup", "neutral", "cup"}}},
    {"H3", "kitchen",
     {{"smartphone", "hot", "hot phone"}, {"sponge", "hot", "hot sponge"}},
     {{"orange", "neutral", "orange"}, {"cup", "hot", "cup"}}},
};
static const char *const k_instr[3][2] = {
    {"pick up the hot cup and place it on the mat", "pick up the normal cup and place it on the mat"},
    {"pick up the iced can and place it on the mat", "pick up the normal can and place it on the mat"},
    {"pick up the hot phone and place it on the mat",
     "pick up the hot sponge and place it on the mat"},
};

/* nominal spots on the table top (x towards the front camera, y to the
 * image's right): slot A, slot B, distractor 1 (behind slot B, where even
 * the kettle stays in view and clear of the hand), distractor 2 (front).
 * The slots are 19 cm apart so the 18 cm wide hand fits beside the other
 * candidate at any jitter */
static const double k_spots[4][2] = {{0.05, 0.00}, {0.05, 0.19}, {-0.17, 0.29}, {0.20, -0.07}};
static const double k_mat[2] = {-0.05, -0.22}, k_mat_half = 0.08;
static const double k_robot_base[3] = {-0.66, 0.0, 0.912};
static const double k_pad_half_z = 0.022;
static const double k_q_start[7] = {0, -0.161, 0, -2.445, 0, 2.227, 0.78539816339744831};

hearth_sim_task hearth_sim_task_parse(const char *s) {
  if (!s) return 0;
  if ((s[0] == 'H' || s[0] == 'h') && s[1] >= '1' && s[1] <= '3' && s[2] == 0)
    return (hearth_sim_task)(s[1] - '0');
  return 0;
}
const char *hearth_sim_task_name(hearth_sim_task t) {
  return t >= 1 && t <= 3 ? k_tasks[t - 1].name : "?";
}
const char *hearth_sim_instruction_text(hearth_sim_task t, int i) {
  if (t < 1 || t > 3 || i < 0 || i > 1) return "";
  return k_instr[t - 1][i];
}

void hearth_sim_opts_default(hearth_sim_opts *o) {
  memset(o, 0, sizeof *o);
  o->task = HEARTH_SIM_H1;
  o->use_ground_truth = 1;
  o->width = o->height = 256;
  o->max_steps = 400;
  o->render_wrist = 1;
}

/* ---- locale-independent MJCF text ---------------------------------------- */
typedef struct num_s { char s[40]; } num_s;
static num_s F(double x) {
  num_s n;
  if (hearth_format_fixed(n.s, sizeof n.s, x, 6) < 0) snprintf(n.s, sizeof n.s, "0");
  return n;
}
typedef struct sbuf { char *p; size_t n, cap; int oom; } sbuf;
static void sb_printf(sbuf *b, const char *fmt, ...) {
  if (b->oom) return;
  for (;;) {
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(b->p ? b->p + b->n : NULL, b->p ? b->cap - b->n : 0, fmt, ap);
    va_end(ap);
    if (k < 0) { b->oom = 1; return; }
    if (b->p && b->n + (size_t)k < b->cap) { b->n += (size_t)k; return; }
    size_t nc = (b->cap ? b->cap * 2 : 65536) + (size_t)k;
    char *q = realloc(b->p, nc);
    if (!q) { b->oom = 1; return; }
    b->p = q, b->cap = nc;
  }
}

static hearth_status write_obj(const char *path, const hearth_mesh *m, hearth_err *err) {
  hearth_atomic_file af;
  hearth_status st = hearth_atomic_open(&af, path, err);
  if (st) return st;
  for (size_t i = 0; i < m->n_vertices; i++)
    fprintf(af.fp, "v %s %s %s\n", F(m->positions[3 * i]).s, F(m->positions[3 * i + 1]).s,
            F(m->positions[3 * i + 2]).s);
  /* OBJ's v runs upwards, glTF's downwards */
  for (size_t i = 0; i < m->n_vertices; i++)
    fprintf(af.fp, "vt %s %s\n", F(m->uvs[2 * i]).s, F(1.0 - m->uvs[2 * i + 1]).s);
  for (size_t t = 0; t < m->n_triangles; t++) {
    unsigned a = m->indices[3 * t] + 1, b = m->indices[3 * t + 1] + 1, c = m->indices[3 * t + 2] + 1;
    fprintf(af.fp, "f %u/%u %u/%u %u/%u\n", a, a, b, b, c, c);
  }
  return hearth_atomic_commit(&af, err);
}

/* modified DH rows (a_{i-1}, d_i, alpha_{i-1}) of the Panda, then the flange */
static const double k_dh[8][3] = {{0, 0.333, 0},        {0, 0, -M_PI / 2},   {0, 0.316, M_PI / 2},
                                  {0.0825, 0, M_PI / 2}, {-0.0825, 0.384, -M_PI / 2},
                                  {0, 0, M_PI / 2},      {0.088, 0, M_PI / 2}, {0, 0.107, 0}};
static const double k_link_mass[7] = {4.0, 4.0, 3.0, 3.0, 2.5, 1.5, 0.6};
static const double k_tau_max[7] = {87, 87, 87, 87, 12, 12, 12};
static const double k_jlo[7] = {-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973};
static const double k_jhi[7] = {2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973};

static void dh_child(int row, double pos[3], double quat[4]) {
  double a = k_dh[row][0], d = k_dh[row][1], al = k_dh[row][2];
  pos[0] = a, pos[1] = -sin(al) * d, pos[2] = cos(al) * d;
  quat[0] = cos(al / 2), quat[1] = sin(al / 2), quat[2] = 0, quat[3] = 0;
}

static void emit_robot(sbuf *b) {
  const char *rob = "contype=\"2\" conaffinity=\"1\" group=\"1\"";
  sb_printf(b, "<body name=\"base\" pos=\"%s %s %s\">\n", F(k_robot_base[0]).s, F(k_robot_base[1]).s,
            F(k_robot_base[2]).s);
  sb_printf(b, "<geom type=\"cylinder\" size=\"0.09 0.45\" pos=\"0 0 -0.45\" material=\"robot_dark\" %s/>\n", rob);
  for (int i = 0; i < 7; i++) {
    double p[3], q[4];
    dh_child(i, p, q);
    sb_printf(b, "<body name=\"link%d\" pos=\"%s %s %s\" quat=\"%s %s %s %s\">\n", i + 1, F(p[0]).s,
              F(p[1]).s, F(p[2]).s, F(q[0]).s, F(q[1]).s, F(q[2]).s, F(q[3]).s);
    sb_printf(b, "<inertial pos=\"0 0 0\" mass=\"%s\" diaginertia=\"0.02 0.02 0.01\"/>\n",
              F(k_link_mass[i]).s);
    sb_printf(b, "<joint name=\"j%d\" axis=\"0 0 1\" range=\"%s %s\" damping=\"0.1\" armature=\"0.1\"/>\n",
              i + 1, F(k_jlo[i]).s, F(k_jhi[i]).s);
    /* a joint housing along the axis, and a capsule to the next joint */
    double rj = i < 4 ? 0.06 : 0.05;
    sb_printf(b, "<geom type=\"cylinder\" size=\"%s 0.055\" material=\"robot_white\" %s/>\n", F(rj).s, rob);
    double c[3], cq[4];
    dh_child(i + 1, c, cq);
    if (hearth_norm3(c) > 1e-6)
      sb_printf(b, "<geom type=\"capsule\" fromto=\"0 0 0 %s %s %s\" size=\"%s\" material=\"robot_white\" %s/>\n",
                F(c[0]).s, F(c[1]).s, F(c[2]).s, F(rj * 0.9).s, rob);
  }
  /* flange and hand: fingers close along the hand's y axis */
  double p[3], q[4];
  dh_child(7, p, q);
  sb_printf(b, "<body name=\"hand\" pos=\"%s %s %s\" quat=\"%s 0 0 %s\">\n", F(p[0]).s, F(p[1]).s,
            F(p[2]).s, F(cos(-M_PI / 8)).s, F(sin(-M_PI / 8)).s);
  sb_printf(b, "<inertial pos=\"0 0 0.03\" mass=\"0.7\" diaginertia=\"0.003 0.002 0.002\"/>\n");
  sb_printf(b, "<geom type=\"box\" size=\"0.025 0.09 0.025\" pos=\"0 0 0.035\" material=\"robot_white\" %s/>\n", rob);
  sb_printf(b, "<geom type=\"cylinder\" size=\"0.04 0.01\" pos=\"0 0 0.005\" material=\"robot_dark\" %s/>\n", rob);
  sb_printf(b, "<camera name=\"eye_in_hand\" pos=\"0.07 0 0.02\" quat=\"0 1 0 0\" fovy=\"75\"/>\n");
  sb_printf(b, "<site name=\"grip\" pos=\"0 0 0.1034\" size=\"0.005\" rgba=\"1 0 0 0\"/>\n");
  for (int s = 0; s < 2; s++) {
    double sign = s == 0 ? 1 : -1;
    sb_printf(b, "<body name=\"finger_%s\" pos=\"0 0 0.0584\">\n", s == 0 ? "left" : "right");
    sb_printf(b, "<inertial pos=\"0 0 0.03\" mass=\"0.03\" diaginertia=\"1e-5 1e-5 1e-5\"/>\n");
    /* damping caps the closing speed near 0.2 m/s (under 0.4 mm per
     * physics step at the 15 N force limit) so the pads cannot tunnel
     * through thin objects such as a phone; 15 N holds the heaviest
     * candidate (0.3 kg) with a wide margin and keeps the pads from sinking
     * into light objects' soft contacts */
    sb_printf(b, "<joint name=\"finger_%d\" type=\"slide\" axis=\"0 %s 0\" range=\"0 0.04\" damping=\"80\" armature=\"0.01\"/>\n",
              s + 1, F(sign).s);
    sb_printf(b, "<geom name=\"pad_%d\" type=\"box\" size=\"0.011 0.006 %s\" pos=\"0 %s 0.045\" "
              "friction=\"2 0.02 0.001\" condim=\"4\" solref=\"0.005 1\" solimp=\"0.95 0.99 0.001\" material=\"robot_dark\" %s/>\n",
              s + 1, F(k_pad_half_z).s, F(sign * 0.006).s, rob);
    sb_printf(b, "</body>\n");
  }
  sb_printf(b, "</body>\n");
  for (int i = 0; i < 7; i++) sb_printf(b, "</body>\n");
  sb_printf(b, "</body>\n");
}

/* ---- env construction ---------------------------------------------------- */
static hearth_status build_xml(hearth_sim_env *e, const char *xml_path, hearth_err *err) {
  const task_def *td = &k_tasks[e->task - 1];
  int study = strcmp(td->scene, "study") == 0;
  sbuf b = {0};
  sb_printf(&b, "<mujoco model=\"hearth_%s\">\n<compiler angle=\"radian\" autolimits=\"true\" meshdir=\"%s\" texturedir=\"%s\"/>\n",
            td->name, e->work_dir, e->work_dir);
  sb_printf(&b, "<option timestep=\"%s\" impratio=\"10\" cone=\"elliptic\"/>\n", F(HEARTH_SIM_TIMESTEP).s);
  /* one sample per pixel: the thermal view's pixels are then exactly the
   * texture's (no edge blends with the room colour), and the CPU renderer
   * is 1.5x faster. The shadow map, when on, is rendered on the CPU for
   * every lit view: sized to the images (4 texels per pixel, 256..2048) */
  int side = e->width > e->height ? e->width : e->height;
  int shadow = side * 4 < 256 ? 256 : side * 4 > 2048 ? 2048 : side * 4;
  sb_printf(&b, "<visual><global offwidth=\"%d\" offheight=\"%d\"/><quality shadowsize=\"%d\" offsamples=\"0\"/>"
            "<headlight ambient=\"0.35 0.35 0.35\" diffuse=\"0.45 0.45 0.45\" specular=\"0.1 0.1 0.1\"/></visual>\n",
            e->width, e->height, shadow);
  sb_printf(&b, "<asset>\n");
  sb_printf(&b, "<texture name=\"floor_tex\" type=\"2d\" builtin=\"checker\" rgb1=\"%s\" rgb2=\"%s\" width=\"256\" height=\"256\"/>\n",
            study ? "0.45 0.42 0.40" : "0.75 0.75 0.72", study ? "0.40 0.37 0.35" : "0.65 0.65 0.62");
  sb_printf(&b, "<material name=\"floor\" texture=\"floor_tex\" texrepeat=\"8 8\"/>\n");
  sb_printf(&b, "<material name=\"table\" rgba=\"%s\" specular=\"0.1\"/>\n",
            study ? "0.55 0.38 0.22 1" : "0.86 0.86 0.84 1");
  sb_printf(&b, "<material name=\"wall\" rgba=\"%s\" specular=\"0\"/>\n",
            study ? "0.78 0.74 0.66 1" : "0.85 0.87 0.88 1");
  sb_printf(&b, "<material name=\"mat\" rgba=\"0.15 0.35 0.65 1\" specular=\"0\"/>\n");
  sb_printf(&b, "<material name=\"robot_white\" rgba=\"0.92 0.92 0.92 1\" specular=\"0.3\"/>\n");
  sb_printf(&b, "<material name=\"robot_dark\" rgba=\"0.2 0.2 0.22 1\" specular=\"0.2\"/>\n");
  for (int k = 0; k < SIM_NOBJ; k++) {
    sb_printf(&b, "<mesh name=\"mesh%d\" file=\"obj%d.obj\"/>\n", k, k);
    sb_printf(&b, "<texture name=\"rgb%d\" type=\"2d\" file=\"rgb%d.png\"/>\n", k, k);
    sb_printf(&b, "<material name=\"mrgb%d\" texture=\"rgb%d\" specular=\"0.15\" shininess=\"0.2\"/>\n", k, k);
    sb_printf(&b, "<texture name=\"th%d\" type=\"2d\" file=\"th%d.png\"/>\n", k, k);
    sb_printf(&b, "<material name=\"mth%d\" texture=\"th%d\" emission=\"1\" specular=\"0\" shininess=\"0\" reflectance=\"0\"/>\n", k, k);
  }
  sb_printf(&b, "</asset>\n<worldbody>\n");
  sb_printf(&b, "<light pos=\"0.3 0.6 2.6\" dir=\"-0.2 -0.4 -1\" diffuse=\"0.5 0.5 0.5\" castshadow=\"%s\"/>\n",
            e->shadows ? "true" : "false");
  sb_printf(&b, "<geom name=\"floor\" type=\"box\" size=\"3 3 0.01\" pos=\"0 0 -0.01\" material=\"floor\" group=\"0\"/>\n");
  /* a back wall behind the robot: the front camera's upper rays pass the
   * floor's far edge, and the thermal view must show room temperature
   * there rather than an empty (black) background */
  sb_printf(&b, "<geom name=\"wall\" type=\"box\" size=\"0.02 3 1.5\" pos=\"-2 0 1.5\" material=\"wall\" group=\"0\"/>\n");
  double tz = HEARTH_SIM_TABLE_Z;
  sb_printf(&b, "<geom name=\"table\" type=\"box\" size=\"0.5 0.6 0.025\" pos=\"0 0 %s\" material=\"table\" friction=\"1 0.005 0.0001\" group=\"0\"/>\n",
            F(tz - 0.025).s);
  for (int i = 0; i < 4; i++)
    sb_printf(&b, "<geom type=\"box\" size=\"0.025 0.025 %s\" pos=\"%s %s %s\" material=\"table\" group=\"0\"/>\n",
              F((tz - 0.05) / 2).s, F(i & 1 ? 0.44 : -0.44).s, F(i & 2 ? 0.54 : -0.54).s, F((tz - 0.05) / 2).s);
  sb_printf(&b, "<geom name=\"mat\" type=\"box\" size=\"%s %s 0.001\" pos=\"%s %s %s\" material=\"mat\" group=\"0\"/>\n",
            F(k_mat_half).s, F(k_mat_half).s, F(k_mat[0]).s, F(k_mat[1]).s, F(tz + 0.001).s);
  /* front camera: LIBERO's agentview position, looking down at the table */
  {
    double eye[3] = {0.66, 0, 1.61}, tgt[3] = {-0.08, 0, tz}, f[3], x[3] = {0, 1, 0}, z[3], y[3];
    for (int i = 0; i < 3; i++) f[i] = tgt[i] - eye[i];
    double n = hearth_norm3(f);
    for (int i = 0; i < 3; i++) z[i] = -f[i] / n;
    hearth_cross3(z, x, y);
    sb_printf(&b, "<camera name=\"agentview\" pos=\"%s %s %s\" xyaxes=\"%s %s %s %s %s %s\" fovy=\"45\"/>\n",
              F(eye[0]).s, F(eye[1]).s, F(eye[2]).s, F(x[0]).s, F(x[1]).s, F(x[2]).s, F(y[0]).s,
              F(y[1]).s, F(y[2]).s);
  }
  emit_robot(&b);
  for (int k = 0; k < SIM_NOBJ; k++) {
    const sim_asset *a = &e->assets[k];
    double h = a->size[2];
    sb_printf(&b, "<body name=\"obj%d\" pos=\"%s %s %s\">\n<freejoint name=\"obj%d_free\"/>\n", k,
              F(k_spots[k][0]).s, F(k_spots[k][1]).s, F(tz + 0.002).s, k);
    double sx = a->size[0], sy = a->size[1], mm = a->mass;
    sb_printf(&b, "<inertial pos=\"0 0 %s\" mass=\"%s\" diaginertia=\"%s %s %s\"/>\n", F(0.45 * h).s, F(mm).s,
              F(mm * (sy * sy + h * h) / 12).s, F(mm * (sx * sx + h * h) / 12).s,
              F(mm * (sx * sx + sy * sy) / 12).s);
    /* MuJoCo 2.2 gives one contact point for mesh collisions, so objects
     * collide through their bounding box (box-box gives stable multi-point
     * contacts); the meshes are visual only */
    sb_printf(&b, "<geom name=\"obj%d_col\" type=\"box\" size=\"%s %s %s\" pos=\"0 0 %s\" group=\"4\" "
              "contype=\"1\" conaffinity=\"1\" condim=\"4\" friction=\"%s 0.01 0.0005\" rgba=\"1 1 1 0\"/>\n",
              k, F(0.5 * sx).s, F(0.5 * a->size[1]).s, F(0.5 * h).s, F(0.5 * h).s, F(a->friction).s);
    sb_printf(&b, "<geom name=\"obj%d_rgb\" type=\"mesh\" mesh=\"mesh%d\" material=\"mrgb%d\" group=\"2\" "
              "contype=\"0\" conaffinity=\"0\"/>\n", k, k, k);
    sb_printf(&b, "<geom name=\"obj%d_th\" type=\"mesh\" mesh=\"mesh%d\" material=\"mth%d\" group=\"3\" "
              "contype=\"0\" conaffinity=\"0\"/>\n</body>\n", k, k, k);
  }
  sb_printf(&b, "</worldbody>\n<contact><exclude body1=\"hand\" body2=\"finger_left\"/>"
            "<exclude body1=\"hand\" body2=\"finger_right\"/></contact>\n<actuator>\n");
  for (int i = 0; i < 7; i++)
    sb_printf(&b, "<motor name=\"m%d\" joint=\"j%d\" ctrllimited=\"true\" ctrlrange=\"%s %s\"/>\n", i + 1,
              i + 1, F(-k_tau_max[i]).s, F(k_tau_max[i]).s);
  for (int s = 0; s < 2; s++)
    sb_printf(&b, "<position name=\"g%d\" joint=\"finger_%d\" kp=\"800\" ctrllimited=\"true\" ctrlrange=\"0 0.04\" "
              "forcelimited=\"true\" forcerange=\"-15 15\"/>\n", s + 1, s + 1);
  sb_printf(&b, "</actuator>\n</mujoco>\n");
  if (b.oom) {
    free(b.p);
    return hearth_err_set(err, HEARTH_E_NOMEM, "sim: out of memory building the MJCF");
  }
  hearth_status st = hearth_write_file_atomic(xml_path, b.p, b.n, err);
  free(b.p);
  return st;
}

void hearth_sim_env_free(hearth_sim_env *e) {
  if (!e) return;
  sim_render_free(e);
  if (e->d) mj_deleteData(e->d);
  if (e->m) mj_deleteModel(e->m);
  for (int k = 0; k < SIM_NOBJ; k++) sim_asset_free(&e->assets[k]);
  if (e->own_work_dir && e->work_dir[0]) hearth_remove_tree(e->work_dir, NULL);
  free(e);
}

hearth_status hearth_sim_env_new(const hearth_sim_opts *o, hearth_sim_env **out, hearth_err *err) {
  *out = NULL;
  if (!o || o->task < 1 || o->task > 3)
    return hearth_err_set(err, HEARTH_E_ARG, "sim: task must be H1, H2 or H3");
  if (!o->release_root) return hearth_err_set(err, HEARTH_E_ARG, "sim: no asset release root");
  if (o->width < 16 || o->height < 16 || o->width > 4096 || o->height > 4096)
    return hearth_err_set(err, HEARTH_E_RANGE, "sim: image size %dx%d outside 16..4096", o->width,
                          o->height);
  hearth_sim_env *e = calloc(1, sizeof *e);
  if (!e) return hearth_err_set(err, HEARTH_E_NOMEM, "sim: out of memory");
  e->task = o->task;
  e->width = o->width, e->height = o->height;
  e->max_steps = o->max_steps > 0 ? o->max_steps : 400;
  e->render_wrist = o->render_wrist;
  e->shadows = o->shadows;
  const char *gl = o->gl && *o->gl ? o->gl : getenv("HEARTH_GL");
  if (!gl || !*gl) gl = "osmesa";
  if (strcmp(gl, "osmesa") != 0 && strcmp(gl, "egl") != 0) {
    free(e);
    return hearth_err_set(err, HEARTH_E_ARG, "sim: renderer '%s' is not osmesa or egl (option gl / HEARTH_GL)", gl);
  }
  snprintf(e->gl, sizeof e->gl, "%s", gl);
  hearth_status st = HEARTH_OK;
  if (o->work_dir) {
    snprintf(e->work_dir, sizeof e->work_dir, "%s", o->work_dir);
    st = hearth_mkdirs(e->work_dir, err);
  } else {
    const char *tmp = getenv("TMPDIR");
    snprintf(e->work_dir, sizeof e->work_dir, "%s/hearth_sim_XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(e->work_dir)) {
      st = hearth_err_set(err, HEARTH_E_IO, "%s: cannot create a scratch directory", e->work_dir);
      e->work_dir[0] = 0;
    } else {
      e->own_work_dir = 1;
    }
  }
  /* assets: two candidates, two distractors */
  const task_def *td = &k_tasks[e->task - 1];
  for (int k = 0; k < SIM_NOBJ && !st; k++) {
    const task_obj *to = k < 2 ? &td->cand[k] : &td->dist[k - 2];
    st = sim_asset_load(o->release_root, o->use_ground_truth, to->category, to->state, &e->assets[k], err);
    char p[4200];
    if (!st) {
      snprintf(p, sizeof p, "%s/obj%d.obj", e->work_dir, k);
      st = write_obj(p, &e->assets[k].mesh, err);
    }
    if (!st) {
      snprintf(p, sizeof p, "%s/rgb%d.png", e->work_dir, k);
      st = hearth_png_write(p, &e->assets[k].rgb, err);
    }
    if (!st) {
      snprintf(p, sizeof p, "%s/th%d.png", e->work_dir, k);
      st = hearth_png_write(p, &e->assets[k].thermal, err);
    }
  }
  char xml[4200];
  snprintf(xml, sizeof xml, "%s/scene.xml", e->work_dir);
  if (!st) st = build_xml(e, xml, err);
  if (!st) {
    char msg[1000] = "";
    e->m = mj_loadXML(xml, NULL, msg, sizeof msg);
    if (!e->m) st = hearth_err_set(err, HEARTH_E_PARSE, "%s: MuJoCo: %s", xml, msg);
  }
  if (!st) {
    e->d = mj_makeData(e->m);
    if (!e->d) st = hearth_err_set(err, HEARTH_E_NOMEM, "sim: mj_makeData failed");
  }
  if (!st) {
    mjModel *m = e->m;
    e->site_grip = mj_name2id(m, mjOBJ_SITE, "grip");
    e->cam_front = mj_name2id(m, mjOBJ_CAMERA, "agentview");
    e->cam_wrist = mj_name2id(m, mjOBJ_CAMERA, "eye_in_hand");
    for (int i = 0; i < 7; i++) {
      char nm[16];
      snprintf(nm, sizeof nm, "j%d", i + 1);
      int j = mj_name2id(m, mjOBJ_JOINT, nm);
      e->arm_qadr[i] = m->jnt_qposadr[j], e->arm_dadr[i] = m->jnt_dofadr[j];
    }
    for (int s = 0; s < 2; s++) {
      char nm[16];
      snprintf(nm, sizeof nm, "finger_%d", s + 1);
      int j = mj_name2id(m, mjOBJ_JOINT, nm);
      e->fing_qadr[s] = m->jnt_qposadr[j];
      snprintf(nm, sizeof nm, "pad_%d", s + 1);
      e->pad_geom[s] = mj_name2id(m, mjOBJ_GEOM, nm);
    }
    for (int k = 0; k < SIM_NOBJ; k++) {
      char nm[32];
      snprintf(nm, sizeof nm, "obj%d", k);
      e->obj_body[k] = mj_name2id(m, mjOBJ_BODY, nm);
      snprintf(nm, sizeof nm, "obj%d_free", k);
      int j = mj_name2id(m, mjOBJ_JOINT, nm);
      e->obj_qadr[k] = m->jnt_qposadr[j], e->obj_dadr[k] = m->jnt_dofadr[j];
      snprintf(nm, sizeof nm, "obj%d_rgb", k);
      e->obj_geom_rgb[k] = mj_name2id(m, mjOBJ_GEOM, nm);
      snprintf(nm, sizeof nm, "obj%d_th", k);
      e->obj_geom_th[k] = mj_name2id(m, mjOBJ_GEOM, nm);
    }
    e->mat_geom = mj_name2id(m, mjOBJ_GEOM, "mat");
    st = sim_render_init(e, err);
  }
  if (st) {
    hearth_sim_env_free(e);
    return st;
  }
  *out = e;
  return HEARTH_OK;
}

/* ---- layouts --------------------------------------------------------------- */
void sim_layout(uint64_t seed, uint64_t layout, int attempt, double pos[SIM_NOBJ][2], int *swap) {
  hearth_rng base, r;
  hearth_rng_seed(&base, seed);
  hearth_rng_fork(&base, layout, &r);
  /* attempt k continues the layout's own stream, so attempt 0 is the
   * plain draw and later attempts never depend on the image size */
  for (int a = 0; a <= attempt; a++)
    for (int k = 0; k < SIM_NOBJ; k++) {
      pos[k][0] = k_spots[k][0] + hearth_rng_range(&r, -0.025, 0.025);
      pos[k][1] = k_spots[k][1] + hearth_rng_range(&r, -0.025, 0.025);
    }
  /* candidate identities alternate between the slots: even layouts put
   * candidate 0 in slot A, odd ones in slot B (balanced for any even N) */
  *swap = (int)(layout & 1);
}

void sim_object_pos(const hearth_sim_env *e, int k, double xyz[3]) {
  for (int i = 0; i < 3; i++) xyz[i] = e->d->qpos[e->obj_qadr[k] + i];
}

void sim_place_object(hearth_sim_env *e, int k, const double xyz[3]) {
  double *q = e->d->qpos + e->obj_qadr[k], *v = e->d->qvel + e->obj_dadr[k];
  for (int i = 0; i < 3; i++) q[i] = xyz[i];
  q[3] = 1, q[4] = q[5] = q[6] = 0;
  for (int i = 0; i < 6; i++) v[i] = 0;
  mj_forward(e->m, e->d);
}

/* fraction of object k's surface samples (up to 96 mesh vertices) that the
 * front camera sees: inside its field of view and not hidden by another
 * geom. Ray casts, so it does not depend on the rendered image size */
double sim_visible_frac(const hearth_sim_env *e, int k) {
  const mjModel *m = e->m;
  const mjData *d = e->d;
  const hearth_mesh *me = &e->assets[k].mesh;
  const double *bp = d->xpos + 3 * e->obj_body[k], *bR = d->xmat + 9 * e->obj_body[k];
  const double *cp = d->cam_xpos + 3 * e->cam_front, *cR = d->cam_xmat + 9 * e->cam_front;
  double th = tan(0.5 * m->cam_fovy[e->cam_front] * M_PI / 180.0);
  double aspect = (double)e->width / (double)e->height;
  /* robot, scene and colour meshes; not the thermal copies or the boxes */
  mjtByte groups[mjNGROUP] = {1, 1, 1, 0, 0, 0};
  size_t n = me->n_vertices, stride = n > 96 ? n / 96 : 1;
  int total = 0, seen = 0;
  for (size_t i = 0; i < n && total < 96; i += stride) {
    const float *v = me->positions + 3 * i;
    double p[3], dir[3], c[3];
    for (int r = 0; r < 3; r++)
      p[r] = bp[r] + bR[3 * r] * v[0] + bR[3 * r + 1] * v[1] + bR[3 * r + 2] * v[2];
    for (int r = 0; r < 3; r++) dir[r] = p[r] - cp[r];
    /* camera frame: columns of cam_xmat are its x, y, z axes; it looks along -z */
    for (int r = 0; r < 3; r++) c[r] = cR[r] * dir[0] + cR[3 + r] * dir[1] + cR[6 + r] * dir[2];
    total++;
    if (c[2] > -1e-6 || fabs(c[0] / -c[2]) > th * aspect || fabs(c[1] / -c[2]) > th) continue;
    int gid = -1;
    mjtNum x = mj_ray(m, d, cp, dir, groups, 1, -1, &gid);
    if (gid < 0 || x > 1.0 - 0.01 / hearth_norm3(dir) || m->geom_bodyid[gid] == e->obj_body[k]) seen++;
  }
  return total ? (double)seen / total : 0.0;
}

hearth_status hearth_sim_reset(hearth_sim_env *e, uint64_t seed, uint64_t layout, int instruction,
                               hearth_err *err) {
  if (instruction < 0 || instruction > 1)
    return hearth_err_set(err, HEARTH_E_ARG, "sim reset: instruction must be 0 or 1, got %d", instruction);
  mjModel *m = e->m;
  mjData *d = e->d;
  mj_resetData(m, d);
  e->instruction = instruction;
  e->target = instruction; /* object index of the target */
  for (int i = 0; i < 7; i++) d->qpos[e->arm_qadr[i]] = k_q_start[i];
  for (int s = 0; s < 2; s++) d->qpos[e->fing_qadr[s]] = 0.04;
  /* visibility check: redraw the layout until both candidates are at
   * least SIM_MIN_VISIBLE visible in the front view (else keep the best
   * draw); the draw depends on (seed, layout) only, never on the
   * instruction, so both instructions start from the same state */
  int best = 0;
  double best_vis = -1;
  for (int attempt = 0; attempt < SIM_MAX_ATTEMPTS; attempt++) {
    double pos[SIM_NOBJ][2];
    int swap;
    sim_layout(seed, layout, attempt, pos, &swap);
    e->swap = swap;
    for (int k = 0; k < SIM_NOBJ; k++) {
      int slot = k < 2 ? (k ^ swap) : k;
      double *q = d->qpos + e->obj_qadr[k];
      q[0] = pos[slot][0], q[1] = pos[slot][1], q[2] = HEARTH_SIM_TABLE_Z + 0.0005;
      q[3] = 1, q[4] = q[5] = q[6] = 0;
    }
    mj_forward(m, d);
    double vis = fmin(sim_visible_frac(e, 0), sim_visible_frac(e, 1));
    if (vis > best_vis) best_vis = vis, best = attempt;
    if (vis >= SIM_MIN_VISIBLE) break;
    if (attempt == SIM_MAX_ATTEMPTS - 1 && best != attempt) {
      /* none passed: go back to the best draw */
      sim_layout(seed, layout, best, pos, &swap);
      for (int k = 0; k < SIM_NOBJ; k++) {
        int slot = k < 2 ? (k ^ swap) : k;
        d->qpos[e->obj_qadr[k]] = pos[slot][0], d->qpos[e->obj_qadr[k] + 1] = pos[slot][1];
      }
      mj_forward(m, d);
    }
  }
  e->layout_attempts = best + 1;
  for (int i = 0; i < 3; i++) e->goal_pos[i] = d->site_xpos[3 * e->site_grip + i];
  memcpy(e->goal_R, d->site_xmat + 9 * e->site_grip, sizeof e->goal_R);
  memcpy(e->R0, e->goal_R, sizeof e->R0);
  e->grip_cmd = -1;
  /* let the objects settle with the arm held */
  for (int i = 0; i < 50; i++) {
    mj_step1(m, d);
    sim_osc(e);
    mj_step2(m, d);
  }
  mj_forward(m, d);
  e->steps = 0;
  e->phase = 0;
  e->phase_steps = 0;
  return HEARTH_OK;
}

/* ---- operational-space control ---------------------------------------------- */
static int inv3(const double A[9], double B[9]) {
  double det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
               A[2] * (A[3] * A[7] - A[4] * A[6]);
  if (fabs(det) < 1e-12) return 0;
  double id = 1.0 / det;
  B[0] = (A[4] * A[8] - A[5] * A[7]) * id, B[1] = (A[2] * A[7] - A[1] * A[8]) * id;
  B[2] = (A[1] * A[5] - A[2] * A[4]) * id, B[3] = (A[5] * A[6] - A[3] * A[8]) * id;
  B[4] = (A[0] * A[8] - A[2] * A[6]) * id, B[5] = (A[2] * A[3] - A[0] * A[5]) * id;
  B[6] = (A[3] * A[7] - A[4] * A[6]) * id, B[7] = (A[1] * A[6] - A[0] * A[7]) * id;
  B[8] = (A[0] * A[4] - A[1] * A[3]) * id;
  return 1;
}
/* in-place Gauss-Jordan inverse of an n x n matrix (n <= 7) with pivoting */
static int invn(double *A, int n) {
  double M[7][14];
  for (int i = 0; i < n; i++)
    for (int j = 0; j < 2 * n; j++) M[i][j] = j < n ? A[i * n + j] : (j - n == i);
  for (int c = 0; c < n; c++) {
    int p = c;
    for (int r = c + 1; r < n; r++)
      if (fabs(M[r][c]) > fabs(M[p][c])) p = r;
    if (fabs(M[p][c]) < 1e-12) return 0;
    if (p != c)
      for (int j = 0; j < 2 * n; j++) {
        double t = M[p][j];
        M[p][j] = M[c][j], M[c][j] = t;
      }
    double iv = 1.0 / M[c][c];
    for (int j = 0; j < 2 * n; j++) M[c][j] *= iv;
    for (int r = 0; r < n; r++)
      if (r != c && M[r][c] != 0) {
        double f = M[r][c];
        for (int j = 0; j < 2 * n; j++) M[r][j] -= f * M[c][j];
      }
  }
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) A[i * n + j] = M[i][j + n];
  return 1;
}

/* robosuite's OSC_POSE: kp 150, critical damping, decoupled task-space
 * inertia, gravity/bias compensation, posture null space, torque limits */
void sim_osc(hearth_sim_env *e) {
  mjModel *m = e->m;
  mjData *d = e->d;
  int nv = m->nv;
  double jp[3 * SIM_MAXNV], jr[3 * SIM_MAXNV];
  mj_jacSite(m, d, jp, jr, e->site_grip);
  double J[6][7], Ma[7][7], Mfull[SIM_MAXNV * SIM_MAXNV];
  for (int i = 0; i < 7; i++) {
    int c = e->arm_dadr[i];
    for (int r = 0; r < 3; r++) J[r][i] = jp[r * nv + c], J[r + 3][i] = jr[r * nv + c];
  }
  mj_fullM(m, Mfull, d->qM);
  for (int i = 0; i < 7; i++)
    for (int j = 0; j < 7; j++) Ma[i][j] = Mfull[e->arm_dadr[i] * nv + e->arm_dadr[j]];
  double Mi[49];
  memcpy(Mi, Ma, sizeof Mi);
  if (!invn(Mi, 7)) return;
  /* Lambda^-1 = J Mi J^T */
  double MiJt[7][6], Li[36];
  for (int i = 0; i < 7; i++)
    for (int r = 0; r < 6; r++) {
      double s = 0;
      for (int k = 0; k < 7; k++) s += Mi[i * 7 + k] * J[r][k];
      MiJt[i][r] = s;
    }
  for (int r = 0; r < 6; r++)
    for (int c = 0; c < 6; c++) {
      double s = 0;
      for (int k = 0; k < 7; k++) s += J[r][k] * MiJt[k][c];
      Li[r * 6 + c] = s;
    }
  double Lp_in[9], Lo_in[9], Lp[9], Lo[9], L[36];
  for (int r = 0; r < 3; r++)
    for (int c = 0; c < 3; c++) Lp_in[r * 3 + c] = Li[r * 6 + c], Lo_in[r * 3 + c] = Li[(r + 3) * 6 + c + 3];
  if (!inv3(Lp_in, Lp) || !inv3(Lo_in, Lo)) return;
  memcpy(L, Li, sizeof L);
  if (!invn(L, 6)) return;
  /* errors and velocities at the grip site */
  const double *x = d->site_xpos + 3 * e->site_grip, *R = d->site_xmat + 9 * e->site_grip;
  double qd[7], v[6];
  for (int i = 0; i < 7; i++) qd[i] = d->qvel[e->arm_dadr[i]];
  for (int r = 0; r < 6; r++) {
    v[r] = 0;
    for (int k = 0; k < 7; k++) v[r] += J[r][k] * qd[k];
  }
  double ep[3], eo[3] = {0, 0, 0};
  for (int i = 0; i < 3; i++) ep[i] = e->goal_pos[i] - x[i];
  for (int c = 0; c < 3; c++) {
    double rc[3] = {R[c], R[3 + c], R[6 + c]}, rd[3] = {e->goal_R[c], e->goal_R[3 + c], e->goal_R[6 + c]}, cr[3];
    hearth_cross3(rc, rd, cr);
    for (int i = 0; i < 3; i++) eo[i] += 0.5 * cr[i];
  }
  const double kp = 150.0, kv = 2.0 * sqrt(150.0);
  double fdes[3], tdes[3], w[6];
  for (int i = 0; i < 3; i++) fdes[i] = kp * ep[i] - kv * v[i], tdes[i] = kp * eo[i] - kv * v[3 + i];
  for (int i = 0; i < 3; i++) {
    w[i] = Lp[i * 3] * fdes[0] + Lp[i * 3 + 1] * fdes[1] + Lp[i * 3 + 2] * fdes[2];
    w[3 + i] = Lo[i * 3] * tdes[0] + Lo[i * 3 + 1] * tdes[1] + Lo[i * 3 + 2] * tdes[2];
  }
  double tau[7];
  for (int i = 0; i < 7; i++) {
    tau[i] = 0;
    for (int r = 0; r < 6; r++) tau[i] += J[r][i] * w[r];
  }
  /* null space: p = M (kn (q0 - q) - kvn qd); tau += (I - J^T Jbar^T) p,
   * Jbar = Mi J^T Lambda */
  const double kn = 10.0, kvn = 2.0 * sqrt(10.0);
  double pr[7], p[7], MiP[7], JMiP[6], LJ[6];
  for (int i = 0; i < 7; i++) pr[i] = kn * (k_q_start[i] - d->qpos[e->arm_qadr[i]]) - kvn * qd[i];
  for (int i = 0; i < 7; i++) {
    p[i] = 0;
    for (int k = 0; k < 7; k++) p[i] += Ma[i][k] * pr[k];
  }
  for (int i = 0; i < 7; i++) {
    MiP[i] = 0;
    for (int k = 0; k < 7; k++) MiP[i] += Mi[i * 7 + k] * p[k];
  }
  for (int r = 0; r < 6; r++) {
    JMiP[r] = 0;
    for (int k = 0; k < 7; k++) JMiP[r] += J[r][k] * MiP[k];
  }
  for (int r = 0; r < 6; r++) {
    LJ[r] = 0;
    for (int c = 0; c < 6; c++) LJ[r] += L[r * 6 + c] * JMiP[c];
  }
  for (int i = 0; i < 7; i++) {
    double s = 0;
    for (int r = 0; r < 6; r++) s += J[r][i] * LJ[r];
    tau[i] += p[i] - s;
  }
  for (int i = 0; i < 7; i++) {
    double t = tau[i] + d->qfrc_bias[e->arm_dadr[i]];
    if (t > k_tau_max[i]) t = k_tau_max[i];
    if (t < -k_tau_max[i]) t = -k_tau_max[i];
    d->ctrl[i] = t;
  }
  double g = e->grip_cmd < -1 ? -1 : e->grip_cmd > 1 ? 1 : e->grip_cmd;
  d->ctrl[7] = d->ctrl[8] = 0.04 * (1.0 - g) / 2.0;
}

hearth_status hearth_sim_step(hearth_sim_env *e, const double action[7], hearth_err *err) {
  double a[7];
  for (int i = 0; i < 7; i++) {
    if (!isfinite(action[i]))
      return hearth_err_set(err, HEARTH_E_RANGE, "sim step: action[%d] is not finite", i);
    a[i] = action[i] < -1 ? -1 : action[i] > 1 ? 1 : action[i];
  }
  mjModel *m = e->m;
  mjData *d = e->d;
  mj_forward(m, d);
  /* goal = current + scaled delta, held for the 25 physics steps */
  const double *x = d->site_xpos + 3 * e->site_grip, *R = d->site_xmat + 9 * e->site_grip;
  for (int i = 0; i < 3; i++) e->goal_pos[i] = x[i] + 0.05 * a[i];
  double w[3] = {0.5 * a[3], 0.5 * a[4], 0.5 * a[5]}, dR[9];
  hearth_rotvec_to_matrix(w, dR);
  hearth_mat3_mul(dR, R, e->goal_R);
  e->grip_cmd = a[6];
  int sub = (int)lround(1.0 / (HEARTH_SIM_CONTROL_HZ * HEARTH_SIM_TIMESTEP));
  for (int s = 0; s < sub; s++) {
    mj_step1(m, d);
    sim_osc(e);
    mj_step2(m, d);
  }
  mj_forward(m, d);
  for (int i = 0; i < m->nq; i++)
    if (!isfinite(d->qpos[i]))
      return hearth_err_set(err, HEARTH_E_NUMERIC, "sim step %d: the simulation diverged", e->steps);
  e->steps++;
  return HEARTH_OK;
}

/* ---- state, success ---------------------------------------------------------- */
int hearth_sim_steps(const hearth_sim_env *e) { return e->steps; }
int hearth_sim_max_steps(const hearth_sim_env *e) { return e->max_steps; }
const char *hearth_sim_instruction(const hearth_sim_env *e) {
  return k_instr[e->task - 1][e->instruction];
}
size_t hearth_sim_state(const hearth_sim_env *e, double *s, size_t max) {
  size_t n = 1 + (size_t)e->m->nq + (size_t)e->m->nv;
  if (s && max >= n) {
    s[0] = e->d->time;
    memcpy(s + 1, e->d->qpos, sizeof(double) * (size_t)e->m->nq);
    memcpy(s + 1 + e->m->nq, e->d->qvel, sizeof(double) * (size_t)e->m->nv);
  }
  return n;
}

static int touching(const hearth_sim_env *e, int geom_a, int body_b) {
  const mjData *d = e->d;
  for (int i = 0; i < d->ncon; i++) {
    int g1 = d->contact[i].geom1, g2 = d->contact[i].geom2;
    if ((g1 == geom_a && e->m->geom_bodyid[g2] == body_b) ||
        (g2 == geom_a && e->m->geom_bodyid[g1] == body_b))
      return 1;
  }
  return 0;
}

int hearth_sim_success(const hearth_sim_env *e) {
  const mjData *d = e->d;
  int k = e->target;
  const double *q = d->qpos + e->obj_qadr[k], *v = d->qvel + e->obj_dadr[k];
  double top = HEARTH_SIM_TABLE_Z + 0.002;
  if (fabs(q[0] - k_mat[0]) > k_mat_half || fabs(q[1] - k_mat[1]) > k_mat_half) return 0;
  /* resting on the mat: its frame origin (bottom centre) at the mat top,
   * upright enough, slow */
  if (q[2] < top - 0.02 || q[2] > top + 0.02) return 0;
  if (sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) > 0.05) return 0;
  for (int s = 0; s < 2; s++)
    if (touching(e, e->pad_geom[s], e->obj_body[k])) return 0;
  return 1;
}

/* ---- scripted expert ----------------------------------------------------------- */
static double clip1(double x) { return x < -1 ? -1 : x > 1 ? 1 : x; }

void hearth_sim_expert_action(hearth_sim_env *e, double act[7]) {
  const mjData *d = e->d;
  int k = e->target;
  const sim_asset *a = &e->assets[k];
  const double *q = d->qpos + e->obj_qadr[k];
  const double *x = d->site_xpos + 3 * e->site_grip, *R = d->site_xmat + 9 * e->site_grip;
  double h = a->size[2];
  /* grasp at half height, but keep the pads (centred on the grip site,
   * 22 mm half height) 2 mm clear of the table: pressing them into the
   * table stalls the descent and makes the closing pads ride up over thin
   * objects. Tall objects: at most 6 cm up (a firm hold low on the body) */
  double gz = fmin(fmax(0.5 * h, k_pad_half_z + 0.002), 0.06);
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
    tgt[0] = q[0], tgt[1] = q[1];
    tgt[2] = fmax(fmax(q[2] + h + 0.08, lift_z - 0.04), HEARTH_SIM_TABLE_Z + tallest + k_pad_half_z + 0.04);
    tol = 0.015;
    next = 1;
    break;
  }
  case 1: /* down to the grasp height */
    tgt[0] = q[0], tgt[1] = q[1], tgt[2] = q[2] + gz;
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
    tgt[0] = k_mat[0], tgt[1] = k_mat[1], tgt[2] = lift_z;
    grip = 1;
    tol = 0.015;
    next = 1;
    break;
  case 5: /* lower until the object is just above the mat */
    tgt[0] = k_mat[0], tgt[1] = k_mat[1], tgt[2] = HEARTH_SIM_TABLE_Z + 0.002 + gz + 0.012;
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
  /* keep the start orientation: axis-angle of R0 R^T */
  double Rt[9], dR[9], w[3];
  hearth_mat3_transpose(R, Rt);
  hearth_mat3_mul(e->R0, Rt, dR);
  hearth_matrix_to_rotvec(dR, w);
  for (int i = 0; i < 3; i++) act[3 + i] = clip1(w[i] / 0.5);
  act[6] = grip;
  e->phase_steps++;
  int done = 0;
  if (e->phase == 2 || e->phase == 6) done = next;
  else if (e->phase < 7) done = dist < tol || (e->phase_steps > 60);
  if (done && e->phase < 7) e->phase++, e->phase_steps = 0;
}
