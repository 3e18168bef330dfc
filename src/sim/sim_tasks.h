/* private: the task table (paper, Table III), the table-top spots and the
 * layout draw (sim_tasks.c) */
#ifndef HEARTH_SIM_TASKS_H
#define HEARTH_SIM_TASKS_H

#include <stdint.h>
#include "hearth/sim.h"

/* objects per scene: 0, 1 the candidates (instruction i targets i), 2, 3
 * the distractors */
#define SIM_NOBJ 4

typedef struct sim_task_obj {
  const char *category, *state, *noun;
} sim_task_obj;
typedef struct sim_task_def {
  const char *name, *scene; /* "H1", "study" or "kitchen"; name NULL: no such task */
  sim_task_obj cand[2];     /* instruction i targets cand[i] */
  sim_task_obj dist[2];
  /* tasks of changing temperatures: dynamic forced, whatever the options
   * ask, at `speedup` thermal seconds per simulated second */
  int dynamic;
  double speedup;
  /* thermal seconds candidate i cooled (or warmed) in still air on the
   * table before the episode starts (H5: filled earlier) */
  double age_s[2];
  /* H6: the episode fails once the target's mean temperature (heat
   * capacity weighted over its regions) passes this, degC, when it started
   * below it; 0: no limit */
  double warm_limit_c;
  /* H4: candidate 0 is a pot with two handles alike in colour, the target
   * of both instructions; the layout's swap bit picks which handle is hot
   * (sim_handles.c), not the candidates' slots; a finger touching the pot
   * above handle_limit_c (degC) fails the episode. Static temperatures */
  int handles;
  double handle_limit_c;
  /* the table-top spots of this task's objects (slot A, slot B,
   * distractors); NULL: sim_spots */
  const double (*spots)[2];
} sim_task_def;
/* The row of a valid task (hearth_sim_task_valid). */
const sim_task_def *sim_task_get(hearth_sim_task t);
/* The object (0..3) instruction ins targets: ins, or 0 for a task of
 * handles. */
int sim_task_target(const sim_task_def *td, int ins);
/* The task's table-top spots (td->spots, else sim_spots). */
const double (*sim_task_spots(const sim_task_def *td))[2];

/* How a scene looks (after LIBERO's study and kitchen table scenes): RGB
 * colours of the checkered floor (and its repeats over the 6 m floor), the
 * table top and legs, the walls, and the front camera's height above the
 * table top (LIBERO's agentview sits 0.743 m above its study table, 0.710
 * m above its kitchen table). */
typedef struct sim_scene_look {
  const char *name;
  double floor1[3], floor2[3];
  int floor_repeat;
  double table[3], wall[3];
  double cam_height;
} sim_scene_look;
/* The look of scene "study" or "kitchen" (the kitchen for any other name). */
const sim_scene_look *sim_scene_look_get(const char *scene);

/* The front camera ("agentview") as LIBERO places it: 0.6586 m in front of
 * the table centre, looking back along -x and down 38.9 degrees, so that its
 * optical axis meets the table top at x = -0.22 (orientation as a w x y z
 * quaternion, x axis along world +y). */
#define SIM_CAM_FRONT_X 0.6586131746834771
extern const double sim_cam_front_quat[4];

/* Nominal spots on the table top (world x, y; x towards the front camera,
 * y to the image's right): slot A, slot B, distractor 1, distractor 2; and
 * the mat (centre, half side), where the target must end. */
extern const double sim_spots[SIM_NOBJ][2];
extern const double sim_mat_centre[2];
#define SIM_MAT_HALF 0.08

/* Draw `attempt` of layout `layout` of the stream `seed`: the jittered
 * positions of the four spots (spots: sim_task_spots) and whether the
 * candidates swap slots (H4: whether the cool handle is the one of slot B). */
void sim_layout(uint64_t seed, uint64_t layout, int attempt, const double (*spots)[2],
                double pos[SIM_NOBJ][2], int *swap);

#endif
