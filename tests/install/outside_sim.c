/* An outside program built with `pkg-config --cflags --libs hearth-sim`
 * against an installed hearth: it calls into the sim and eval areas (which
 * bring MuJoCo, OSMesa and HDF5 onto the link line). Exit 0 when every
 * check holds. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/hearth.h"

int main(void) {
  int failures = 0;
#define EXPECT(cond)                                                       \
  do {                                                                     \
    if (!(cond)) {                                                         \
      fprintf(stderr, "outside_sim.c:%d: expected %s\n", __LINE__, #cond); \
      failures++;                                                          \
    }                                                                      \
  } while (0)
  EXPECT(hearth_sim_task_parse("h2") == HEARTH_SIM_H2);
  EXPECT(!strcmp(hearth_sim_task_name(HEARTH_SIM_H3), "H3"));
  EXPECT(hearth_sim_instruction_text(HEARTH_SIM_H1, 0) != NULL);
  hearth_sim_opts so;
  hearth_sim_opts_default(&so);
  EXPECT(so.width > 0 && so.max_steps > 0);
  EXPECT(hearth_eval_time_limit(HEARTH_SIM_H1) > 0);
  hearth_eval_opts eo;
  hearth_eval_opts_default(&eo);
  EXPECT(eo.episodes > 0);
  if (failures) fprintf(stderr, "outside_sim: %d check(s) failed\n", failures);
  else printf("outside_sim: every check passed\n");
  return failures ? 1 : 0;
}
