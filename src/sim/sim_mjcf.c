/* The scene as MuJoCo reads it: the MJCF text of the room, table, mat,
 * cameras, robot and objects, and the OBJ meshes it names. */
#include <stdio.h>
#include <string.h>

#include "sim/sim_env.h"
#include "sim/sim_mjcf.h"
#include "sim/sim_robot.h"

hearth_status sim_obj_write(const char *path, const hearth_mesh *m, hearth_err *err) {
  hearth_atomic_file af;
  hearth_status st = hearth_atomic_open(&af, path, err);
  if (st) return st;
  for (size_t i = 0; i < m->n_vertices; i++)
    fprintf(af.fp, "v %s %s %s\n", sim_num(m->positions[3 * i]).s,
            sim_num(m->positions[3 * i + 1]).s, sim_num(m->positions[3 * i + 2]).s);
  /* OBJ's v runs upwards, glTF's downwards */
  for (size_t i = 0; i < m->n_vertices; i++)
    fprintf(af.fp, "vt %s %s\n", sim_num(m->uvs[2 * i]).s, sim_num(1.0 - m->uvs[2 * i + 1]).s);
  for (size_t t = 0; t < m->n_triangles; t++) {
    unsigned a = m->indices[3 * t] + 1, b = m->indices[3 * t + 1] + 1,
             c = m->indices[3 * t + 2] + 1;
    fprintf(af.fp, "f %u/%u %u/%u %u/%u\n", a, a, b, b, c, c);
  }
  return hearth_atomic_commit(&af, err);
}

void sim_mjcf_scene_text(const hearth_sim_env *e, const char *dir, hearth_strbuf *out) {
  const sim_task_def *td = sim_task_get(e->task);
  const sim_scene_look *lk = sim_scene_look_get(td->scene);
  hearth_strbuf b = *out;
  hearth_strbuf_printf(
      &b,
      "<mujoco model=\"hearth_%s\">\n<compiler angle=\"radian\" autolimits=\"true\" meshdir=\"%s\" texturedir=\"%s\"/>\n",
      td->name, dir, dir);
  hearth_strbuf_printf(&b, "<option timestep=\"%s\" impratio=\"10\" cone=\"elliptic\"/>\n",
                       sim_num(HEARTH_SIM_TIMESTEP).s);
  /* one sample per pixel: the thermal view's pixels are then exactly the
   * texture's (no edge blends with the room colour), and the CPU renderer
   * is 1.5x faster. The shadow map, when on, is rendered on the CPU for
   * every lit view: sized to the images (4 texels per pixel, 256..2048) */
  int side = e->width > e->height ? e->width : e->height;
  int shadow = side * 4 < 256 ? 256 : side * 4 > 2048 ? 2048 : side * 4;
  hearth_strbuf_printf(
      &b,
      "<visual><global offwidth=\"%d\" offheight=\"%d\"/><quality shadowsize=\"%d\" offsamples=\"0\"/>"
      "<headlight ambient=\"0.35 0.35 0.35\" diffuse=\"0.45 0.45 0.45\" specular=\"0.1 0.1 0.1\"/></visual>\n",
      e->width, e->height, shadow);
  hearth_strbuf_printf(&b, "<asset>\n");
  hearth_strbuf_printf(
      &b,
      "<texture name=\"floor_tex\" type=\"2d\" builtin=\"checker\" rgb1=\"%s %s %s\" rgb2=\"%s %s %s\" width=\"256\" height=\"256\"/>\n",
      sim_num(lk->floor1[0]).s, sim_num(lk->floor1[1]).s, sim_num(lk->floor1[2]).s,
      sim_num(lk->floor2[0]).s, sim_num(lk->floor2[1]).s, sim_num(lk->floor2[2]).s);
  hearth_strbuf_printf(&b, "<material name=\"floor\" texture=\"floor_tex\" texrepeat=\"%d %d\"/>\n",
                       lk->floor_repeat, lk->floor_repeat);
  hearth_strbuf_printf(&b, "<material name=\"table\" rgba=\"%s %s %s 1\" specular=\"0.1\"/>\n",
                       sim_num(lk->table[0]).s, sim_num(lk->table[1]).s, sim_num(lk->table[2]).s);
  hearth_strbuf_printf(&b, "<material name=\"wall\" rgba=\"%s %s %s 1\" specular=\"0\"/>\n",
                       sim_num(lk->wall[0]).s, sim_num(lk->wall[1]).s, sim_num(lk->wall[2]).s);
  hearth_strbuf_printf(&b, "<material name=\"mat\" rgba=\"0.15 0.35 0.65 1\" specular=\"0\"/>\n");
  hearth_strbuf_printf(
      &b, "<material name=\"robot_white\" rgba=\"0.92 0.92 0.92 1\" specular=\"0.3\"/>\n");
  hearth_strbuf_printf(&b,
                       "<material name=\"robot_dark\" rgba=\"0.2 0.2 0.22 1\" specular=\"0.2\"/>\n");
  for (int k = 0; k < SIM_NOBJ; k++) {
    hearth_strbuf_printf(&b, "<mesh name=\"mesh%d\" file=\"obj%d.obj\"/>\n", k, k);
    hearth_strbuf_printf(&b, "<texture name=\"rgb%d\" type=\"2d\" file=\"rgb%d.png\"/>\n", k, k);
    hearth_strbuf_printf(
        &b, "<material name=\"mrgb%d\" texture=\"rgb%d\" specular=\"0.15\" shininess=\"0.2\"/>\n",
        k, k);
    hearth_strbuf_printf(&b, "<texture name=\"th%d\" type=\"2d\" file=\"th%d.png\"/>\n", k, k);
    hearth_strbuf_printf(
        &b,
        "<material name=\"mth%d\" texture=\"th%d\" emission=\"1\" specular=\"0\" shininess=\"0\" reflectance=\"0\"/>\n",
        k, k);
  }
  hearth_strbuf_printf(&b, "</asset>\n<worldbody>\n");
  hearth_strbuf_printf(
      &b,
      "<light pos=\"0.3 0.6 2.6\" dir=\"-0.2 -0.4 -1\" diffuse=\"0.5 0.5 0.5\" castshadow=\"%s\"/>\n",
      e->shadows ? "true" : "false");
  hearth_strbuf_printf(
      &b,
      "<geom name=\"floor\" type=\"box\" size=\"3 3 0.01\" pos=\"0 0 -0.01\" material=\"floor\" group=\"0\"/>\n");
  /* a back wall behind the robot: the front camera's upper rays pass the
   * floor's far edge, and the thermal view must show room temperature
   * there rather than an empty (black) background */
  hearth_strbuf_printf(
      &b,
      "<geom name=\"wall\" type=\"box\" size=\"0.02 3 1.5\" pos=\"-2 0 1.5\" material=\"wall\" group=\"0\"/>\n");
  double tz = HEARTH_SIM_TABLE_Z;
  hearth_strbuf_printf(
      &b,
      "<geom name=\"table\" type=\"box\" size=\"0.5 0.6 0.025\" pos=\"0 0 %s\" material=\"table\" friction=\"1 0.005 0.0001\" group=\"0\"/>\n",
      sim_num(tz - 0.025).s);
  for (int i = 0; i < 4; i++)
    hearth_strbuf_printf(
        &b,
        "<geom type=\"box\" size=\"0.025 0.025 %s\" pos=\"%s %s %s\" material=\"table\" group=\"0\"/>\n",
        sim_num((tz - 0.05) / 2).s, sim_num(i & 1 ? 0.44 : -0.44).s,
        sim_num(i & 2 ? 0.54 : -0.54).s, sim_num((tz - 0.05) / 2).s);
  hearth_strbuf_printf(
      &b,
      "<geom name=\"mat\" type=\"box\" size=\"%s %s 0.001\" pos=\"%s %s %s\" material=\"mat\" group=\"0\"/>\n",
      sim_num(SIM_MAT_HALF).s, sim_num(SIM_MAT_HALF).s, sim_num(sim_mat_centre[0]).s,
      sim_num(sim_mat_centre[1]).s, sim_num(tz + 0.001).s);
  /* front camera: LIBERO's agentview pose over this scene's table */
  hearth_strbuf_printf(
      &b, "<camera name=\"agentview\" pos=\"%s 0 %s\" quat=\"%s %s %s %s\" fovy=\"45\"/>\n",
      sim_num(SIM_CAM_FRONT_X).s, sim_num(tz + lk->cam_height).s, sim_num(sim_cam_front_quat[0]).s,
      sim_num(sim_cam_front_quat[1]).s, sim_num(sim_cam_front_quat[2]).s,
      sim_num(sim_cam_front_quat[3]).s);
  sim_robot_emit_bodies(&b);
  for (int k = 0; k < SIM_NOBJ; k++) {
    const sim_asset *a = &e->assets[k];
    double h = a->size[2];
    hearth_strbuf_printf(
        &b, "<body name=\"obj%d\" pos=\"%s %s %s\">\n<freejoint name=\"obj%d_free\"/>\n", k,
        sim_num(sim_task_spots(td)[k][0]).s, sim_num(sim_task_spots(td)[k][1]).s,
        sim_num(tz + 0.002).s, k);
    double sx = a->size[0], sy = a->size[1], mm = a->mass;
    hearth_strbuf_printf(&b, "<inertial pos=\"0 0 %s\" mass=\"%s\" diaginertia=\"%s %s %s\"/>\n",
                         sim_num(0.45 * h).s, sim_num(mm).s, sim_num(mm * (sy * sy + h * h) / 12).s,
                         sim_num(mm * (sx * sx + h * h) / 12).s,
                         sim_num(mm * (sx * sx + sy * sy) / 12).s);
    /* MuJoCo 2.2 gives one contact point for mesh collisions, so objects
     * collide through their bounding box (box-box gives stable multi-point
     * contacts); the meshes are visual only */
    if (k == 0 && td->handles)
      /* H4's pot: its body, lid and two handles, so the fingers can close
       * on a handle */
      sim_handles_mjcf(e, a->friction, &b);
    else
      hearth_strbuf_printf(
          &b,
          "<geom name=\"obj%d_col\" type=\"box\" size=\"%s %s %s\" pos=\"0 0 %s\" group=\"4\" "
          "contype=\"1\" conaffinity=\"1\" condim=\"4\" friction=\"%s 0.01 0.0005\" rgba=\"1 1 1 0\"/>\n",
          k, sim_num(0.5 * sx).s, sim_num(0.5 * a->size[1]).s, sim_num(0.5 * h).s,
          sim_num(0.5 * h).s, sim_num(a->friction).s);
    hearth_strbuf_printf(
        &b,
        "<geom name=\"obj%d_rgb\" type=\"mesh\" mesh=\"mesh%d\" material=\"mrgb%d\" group=\"2\" "
        "contype=\"0\" conaffinity=\"0\"/>\n",
        k, k, k);
    hearth_strbuf_printf(
        &b,
        "<geom name=\"obj%d_th\" type=\"mesh\" mesh=\"mesh%d\" material=\"mth%d\" group=\"3\" "
        "contype=\"0\" conaffinity=\"0\"/>\n</body>\n",
        k, k, k);
  }
  hearth_strbuf_printf(&b, "</worldbody>\n");
  sim_robot_emit_actuators(&b);
  hearth_strbuf_printf(&b, "</mujoco>\n");
  *out = b;
}

hearth_status sim_mjcf_write_scene(const hearth_sim_env *e, const char *xml_path, hearth_err *err) {
  hearth_strbuf b = {0};
  sim_mjcf_scene_text(e, e->work_dir, &b);
  if (b.failed) {
    hearth_strbuf_free(&b);
    return hearth_err_set(err, HEARTH_E_NOMEM, "sim: out of memory building the MJCF");
  }
  hearth_status st = hearth_write_file_atomic(xml_path, b.data, b.len, err);
  hearth_strbuf_free(&b);
  return st;
}
