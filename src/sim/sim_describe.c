/* What a collection file says about its task: LIBERO's and robomimic's
 * file-level attributes (env_name, problem_info, env_args, a BDDL-style
 * description of the scene and goal, the image convention) made from the
 * task table. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/sim_h5.h"
#include "sim/sim_tasks.h"

/* x with three decimals, locale-independent */
typedef struct num3 {
  char s[32];
} num3;
static num3 n3(double x) {
  num3 n;
  if (hearth_format_fixed(n.s, sizeof n.s, x, 3) < 0) snprintf(n.s, sizeof n.s, "0");
  return n;
}

/* "hot cup" -> "hot_cup_1" */
static void obj_name(const sim_task_obj *o, char *out, size_t n) {
  snprintf(out, n, "%s_1", o->noun);
  for (char *p = out; *p; p++)
    if (*p == ' ') *p = '_';
}

/* "pick up the hot cup ..." -> "H1_pick_up_the_hot_cup_..." */
static void file_stem(hearth_sim_task t, int ins, char *out, size_t n) {
  snprintf(out, n, "%s_%s", hearth_sim_task_name(t), hearth_sim_instruction_text(t, ins));
  for (char *p = out; *p; p++)
    if (*p == ' ') *p = '_';
}

static const char *state_words(const char *state) {
  if (strcmp(state, "hot") == 0) return "hot";
  if (strcmp(state, "iced") == 0) return "iced";
  return "room temperature";
}

/* a BDDL-style problem: regions on the table (the layout jitter squares and
 * the mat), the four objects, where they start and the goal of
 * instruction ins */
static void bddl_text(hearth_sim_task t, int ins, hearth_strbuf *b) {
  const sim_task_def *td = sim_task_get(t);
  const sim_task_obj *objs[SIM_NOBJ] = {&td->cand[0], &td->cand[1], &td->dist[0], &td->dist[1]};
  char names[SIM_NOBJ][64];
  for (int k = 0; k < SIM_NOBJ; k++) obj_name(objs[k], names[k], sizeof names[k]);
  const double(*spots)[2] = sim_task_spots(td);
  int target = sim_task_target(td, ins);
  static const char *const k_regions[SIM_NOBJ] = {"slot_a_region", "slot_b_region",
                                                  "distractor_1_region", "distractor_2_region"};
  hearth_strbuf_printf(
      b,
      "; hearth task %s (%s table), the scene of `hearth sim collect` in BDDL form.\n"
      "; Ranges are (x_min y_min x_max y_max) in metres on the table top, whose centre\n"
      "; is the world origin in x and y (x towards the front camera). Objects stand\n"
      "; upright; the candidates look the same in colour and differ in temperature,\n"
      "; which only the thermal view (obs/agentview_thermal) shows.\n",
      td->name, td->scene);
  hearth_strbuf_printf(
      b, "(define (problem hearth_%s)\n  (:domain hearth)\n  (:language %s)\n  (:regions\n",
      td->name, hearth_sim_instruction_text(t, ins));
  for (int k = 0; k < SIM_NOBJ; k++)
    hearth_strbuf_printf(
        b,
        "    (%s\n      (:target main_table)\n      (:ranges (\n          (%s %s %s %s)\n        )\n      )\n    )\n",
        k_regions[k], n3(spots[k][0] - 0.025).s, n3(spots[k][1] - 0.025).s,
        n3(spots[k][0] + 0.025).s, n3(spots[k][1] + 0.025).s);
  hearth_strbuf_printf(
      b,
      "    (mat_region\n      (:target main_table)\n      (:ranges (\n          (%s %s %s %s)\n"
      "        )\n      )\n    )\n  )\n",
      n3(sim_mat_centre[0] - SIM_MAT_HALF).s, n3(sim_mat_centre[1] - SIM_MAT_HALF).s,
      n3(sim_mat_centre[0] + SIM_MAT_HALF).s, n3(sim_mat_centre[1] + SIM_MAT_HALF).s);
  hearth_strbuf_printf(b,
                       "  (:fixtures\n    main_table - table\n    mat_1 - mat\n  )\n  (:objects\n");
  for (int k = 0; k < SIM_NOBJ; k++)
    hearth_strbuf_printf(b, "    %s - %s ; %s\n", names[k], objs[k]->category,
                         state_words(objs[k]->state));
  hearth_strbuf_printf(b, "  )\n  (:obj_of_interest\n    %s\n    mat_1\n  )\n", names[target]);
  hearth_strbuf_printf(
      b,
      "  ; even layouts; odd layouts swap the two candidates' regions\n  (:init\n    (On mat_1 mat_region)\n");
  for (int k = 0; k < SIM_NOBJ; k++)
    hearth_strbuf_printf(b, "    (On %s %s)\n", names[k], k_regions[k]);
  hearth_strbuf_printf(
      b,
      "  )\n  ; success: the object's bottom centre over the mat, within 2 cm of its top,\n"
      "  ; slower than 0.05 m/s and released by both fingers\n"
      "  (:goal\n    (And (On %s mat_1))\n  )\n)\n",
      names[target]);
}

hearth_status sim_h5_describe(const hearth_sim_collect_opts *o, int ins_first, int ins_count,
                              const char *gl, sim_h5_meta *m, hearth_err *err) {
  memset(m, 0, sizeof *m);
  hearth_sim_task t = o->task;
  const char *name = hearth_sim_task_name(t);
  char stem[256], bddl_name[320];
  file_stem(t, ins_first, stem, sizeof stem);
  snprintf(bddl_name, sizeof bddl_name, "bddl_files/hearth/%s.bddl", stem);
  hearth_strbuf b[SIM_H5_NKEYS] = {{0}};
  hearth_strbuf_printf(&b[SIM_H5_ENV_NAME], "hearth_%s", name);
  hearth_strbuf_printf(
      &b[SIM_H5_PROBLEM_INFO],
      "{\"problem_name\": \"hearth_%s\", \"domain_name\": \"hearth\", \"language_instruction\": \"%s\"}",
      name, hearth_sim_instruction_text(t, ins_first));
  hearth_strbuf_printf(
      &b[SIM_H5_ENV_ARGS],
      "{\"env_name\": \"hearth_%s\", \"type\": 1, \"problem_name\": \"hearth_%s\", \"bddl_file\": \"%s\", "
      "\"env_kwargs\": {\"control_freq\": %d, \"camera_heights\": %d, \"camera_widths\": %d, "
      "\"camera_names\": [\"agentview\", \"eye_in_hand\"], \"controller\": \"OSC_POSE\", "
      "\"seed\": %llu, \"asset_source\": \"%s\", \"shadows\": %s, \"renderer\": \"%s\", "
      "\"bddl_file_name\": \"%s\"}}",
      name, name, bddl_name, HEARTH_SIM_CONTROL_HZ, o->image_size, o->image_size,
      (unsigned long long)o->seed,
      o->use_ground_truth ? "virtual_rig_ground_truth" : "release_derived",
      o->shadows ? "true" : "false", gl, bddl_name);
  hearth_strbuf_printf(&b[SIM_H5_BDDL_FILE_NAME], "%s", bddl_name);
  bddl_text(t, ins_first, &b[SIM_H5_BDDL_FILE_CONTENT]);
  hearth_strbuf_printf(&b[SIM_H5_MACROS_IMAGE_CONVENTION], "opengl");
  hearth_strbuf_printf(&b[SIM_H5_INSTRUCTIONS], "[");
  for (int i = 0; i < ins_count; i++)
    hearth_strbuf_printf(&b[SIM_H5_INSTRUCTIONS], "%s\"%s\"", i ? ", " : "",
                         hearth_sim_instruction_text(t, ins_first + i));
  hearth_strbuf_printf(&b[SIM_H5_INSTRUCTIONS], "]");
  hearth_strbuf_printf(&b[SIM_H5_IMAGE_ROW_ORDER], "opengl_bottom_row_first");
  hearth_strbuf_printf(&b[SIM_H5_THERMAL_COLORMAP], "turbo 10..60 degC");
  int failed = 0;
  for (int k = 0; k < SIM_H5_NKEYS; k++) {
    failed |= b[k].failed;
    m->str[k] = hearth_strbuf_take(&b[k]);
    if (!m->str[k]) failed = 1;
  }
  if (failed) {
    sim_h5_meta_free(m);
    return hearth_err_set(err, HEARTH_E_NOMEM, "sim collect: out of memory describing the task");
  }
  return HEARTH_OK;
}
