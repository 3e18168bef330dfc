/* The tasks as data: objects, instructions, where things stand on the
 * table, the thermal set-up of the tasks of changing temperatures, and the
 * layout draw that jitters them. */
#include <string.h>

#include "sim/sim_tasks.h"
#include "hearth/core.h"

/* H4's spots: the pot (its handles reach 13 cm each way) in the middle,
 * the eraser behind it on the robot's side, the distractors clear of the
 * hand at either handle */
static const double k_h4_spots[SIM_NOBJ][2] = {{0.05, 0.07},
                                               {-0.20, 0.10},
                                               {-0.17, 0.33},
                                               {0.21, -0.12}};

/* H1-H3: paper, Table III. H4: the hot pot's cool handle (our choice of
 * task, docs/simulation.md). H5, H6: temperatures that change (dynamic
 * forced; speed-ups and ages measured in docs/simulation.md, "Tasks"). */
#define SIM_NTASK (HEARTH_SIM_TASK_END - 1)
static const sim_task_def k_tasks[SIM_NTASK] = {
    {"H1",
     "study",
     {{"cup", "hot", "hot cup"}, {"cup", "neutral", "normal cup"}},
     {{"electric_kettle", "hot", "kettle"}, {"eraser", "neutral", "eraser"}}},
    {"H2",
     "kitchen",
     {{"canned_drink", "iced", "iced can"}, {"canned_drink", "neutral", "normal can"}},
     {{"orange", "iced", "orange"}, {"cup", "neutral", "cup"}}},
    {"H3",
     "kitchen",
     {{"smartphone", "hot", "hot phone"}, {"sponge", "hot", "hot sponge"}},
     {{"orange", "neutral", "orange"}, {"cup", "hot", "cup"}}},
    /* one hot pot (both instructions target it) with an eraser and two
     * distractors at room temperature */
    {"H4",
     "kitchen",
     {{"pot", "hot", "pot"}, {"eraser", "neutral", "eraser"}},
     {{"cup", "neutral", "cup"}, {"orange", "neutral", "orange"}},
     .handles = 1,
     .handle_limit_c = 45.0,
     .spots = k_h4_spots},
    /* two cups of the same hot asset: the second was filled half an hour
     * before the first, so it starts cooler; both cool during the episode */
    {"H5",
     "study",
     {{"cup", "hot", "warm cup"}, {"cup", "hot", "cold cup"}},
     {{"eraser", "neutral", "eraser"}, {"orange", "neutral", "orange"}},
     1,
     30.0,
     {0.0, 1800.0},
     0.0},
    /* the iced can warms in the room air and on the table; the normal can
     * is at room temperature */
    {"H6",
     "kitchen",
     {{"canned_drink", "iced", "iced can"}, {"canned_drink", "neutral", "normal can"}},
     {{"orange", "neutral", "orange"}, {"cup", "neutral", "cup"}},
     1,
     80.0,
     {0.0, 0.0},
     10.5},
};
static const char *const k_instr[SIM_NTASK][2] = {
    {"pick up the hot cup and place it on the mat",
     "pick up the normal cup and place it on the mat"},
    {"pick up the iced can and place it on the mat",
     "pick up the normal can and place it on the mat"},
    {"pick up the hot phone and place it on the mat",
     "pick up the hot sponge and place it on the mat"},
    {"pick up the pot by its cool handle and put it on the trivet",
     "one handle of the pot is hot: lift the pot by the other one and set it on the trivet"},
    {"bring the cup that is still warm to the mat", "bring the cup that has gone cold to the mat"},
    {"put the iced can back on the mat before it warms up",
     "put the can at room temperature on the mat"},
};

/* distractor 1 stands behind slot B, where even the kettle stays in view
 * and clear of the hand; distractor 2 in front. The slots are 19 cm apart
 * so the 18 cm wide hand fits beside the other candidate at any jitter */
const double sim_spots[SIM_NOBJ][2] = {{0.05, 0.00}, {0.05, 0.19}, {-0.17, 0.29}, {0.20, -0.07}};
const double sim_mat_centre[2] = {-0.05, -0.22};

int hearth_sim_task_valid(hearth_sim_task t) {
  return t >= 1 && t <= SIM_NTASK && k_tasks[t - 1].name != NULL;
}
const sim_task_def *sim_task_get(hearth_sim_task t) { return &k_tasks[t - 1]; }
int sim_task_target(const sim_task_def *td, int ins) { return td->handles ? 0 : ins; }
const double (*sim_task_spots(const sim_task_def *td))[2] {
  return td->spots ? td->spots : sim_spots;
}

/* the study: a light-gray floor and plaster walls around a dark wooden
 * desk; the kitchen: gray ceramic tiles and yellow linen walls around a
 * light wooden table */
static const sim_scene_look k_looks[2] = {
    {"study",
     {0.62, 0.62, 0.61},
     {0.57, 0.57, 0.56},
     8,
     {0.36, 0.24, 0.15},
     {0.80, 0.79, 0.77},
     0.7433500240372424},
    {"kitchen",
     {0.52, 0.52, 0.51},
     {0.44, 0.44, 0.44},
     14,
     {0.78, 0.66, 0.48},
     {0.90, 0.83, 0.60},
     0.7103500240372423},
};

const sim_scene_look *sim_scene_look_get(const char *scene) {
  return strcmp(scene, "study") == 0 ? &k_looks[0] : &k_looks[1];
}

const double sim_cam_front_quat[4] = {0.6380177736282349, 0.3048497438430786, 0.30484986305236816,
                                      0.6380177736282349};

hearth_sim_task hearth_sim_task_parse(const char *s) {
  if (!s) return 0;
  if ((s[0] == 'H' || s[0] == 'h') && s[1] >= '1' && s[1] <= '9' && s[2] == 0 &&
      hearth_sim_task_valid((hearth_sim_task)(s[1] - '0')))
    return (hearth_sim_task)(s[1] - '0');
  return 0;
}
const char *hearth_sim_task_name(hearth_sim_task t) {
  return hearth_sim_task_valid(t) ? k_tasks[t - 1].name : "?";
}
const char *hearth_sim_instruction_text(hearth_sim_task t, int i) {
  if (!hearth_sim_task_valid(t) || i < 0 || i > 1) return "";
  return k_instr[t - 1][i];
}

void sim_layout(uint64_t seed, uint64_t layout, int attempt, const double (*spots)[2],
                double pos[SIM_NOBJ][2], int *swap) {
  hearth_rng base, r;
  hearth_rng_seed(&base, seed);
  hearth_rng_fork(&base, layout, &r);
  /* attempt k continues the layout's own stream, so attempt 0 is the
   * plain draw and later attempts never depend on the image size */
  for (int a = 0; a <= attempt; a++)
    for (int k = 0; k < SIM_NOBJ; k++) {
      pos[k][0] = spots[k][0] + hearth_rng_range(&r, -0.025, 0.025);
      pos[k][1] = spots[k][1] + hearth_rng_range(&r, -0.025, 0.025);
    }
  /* candidate identities alternate between the slots: even layouts put
   * candidate 0 in slot A, odd ones in slot B (balanced for any even N) */
  *swap = (int)(layout & 1);
}
