/* private: MJCF text and the scene files MuJoCo loads (sim_mjcf.c), and
 * the locale-independent numbers every MJCF and OBJ writer uses */
#ifndef HEARTH_SIM_MJCF_H
#define HEARTH_SIM_MJCF_H

#include <stdio.h>
#include "hearth/core.h"
#include "hearth/mesh.h"

typedef struct hearth_sim_env hearth_sim_env;

/* x with six fixed decimals and '.', whatever the locale ("0" if it does
 * not fit): sim_num(x).s */
typedef struct sim_num_text {
  char s[40];
} sim_num_text;
static inline sim_num_text sim_num(double x) {
  sim_num_text n;
  if (hearth_format_fixed(n.s, sizeof n.s, x, 6) < 0) snprintf(n.s, sizeof n.s, "0");
  return n;
}

/* Append the env's scene as MJCF text to out, naming its meshes and
 * textures under dir (the scratch directory for the model MuJoCo loads;
 * "." for the copy stored in collection files). */
void sim_mjcf_scene_text(const hearth_sim_env *e, const char *dir, hearth_strbuf *out);
/* Write the env's scene (room, table, mat, cameras, robot, its four
 * objects at their nominal spots, actuators) as MJCF to xml_path; the
 * meshes and textures it names are e->work_dir/obj<k>.obj, rgb<k>.png and
 * th<k>.png. */
hearth_status sim_mjcf_write_scene(const hearth_sim_env *e, const char *xml_path, hearth_err *err);
/* Write a mesh's positions, texture coordinates (v flipped: OBJ's v runs
 * upwards) and triangles as a Wavefront OBJ file, atomically. */
hearth_status sim_obj_write(const char *path, const hearth_mesh *m, hearth_err *err);

#endif
