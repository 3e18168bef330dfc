/* private: the demos of a `hearth sim collect` HDF5 file, replayed by the
 * evaluation (eval_replay.c) */
#ifndef HEARTH_EVAL_REPLAY_H
#define HEARTH_EVAL_REPLAY_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/sim.h"

/* one demo: data/demo_<index> */
typedef struct eval_replay_demo {
  int index, instruction;
  uint64_t layout;
  size_t T, S;              /* steps; state length (0: no states stored) */
  double *actions, *states; /* T x 7; T x S or NULL */
} eval_replay_demo;

typedef struct eval_replay_file {
  hearth_sim_task task; /* from env_name "hearth_H<k>" */
  uint64_t seed;        /* the layout stream, env_kwargs.seed */
  int n;
  eval_replay_demo *demos;
} eval_replay_file;

/* Load spec "FILE" (every demo) or "FILE#K" (demo K): the task and seed
 * from data.env_args, per demo its layout, instruction, actions (T, 7) and
 * states (T, S) if stored. On failure r is empty. */
hearth_status eval_replay_load(const char *spec, eval_replay_file *r, hearth_err *err);
/* Free the demos and zero r; accepts a zeroed file. */
void eval_replay_free(eval_replay_file *r);

#endif
