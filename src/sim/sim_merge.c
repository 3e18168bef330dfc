/* hearth_sim_merge: the files of a sharded collection back into the file
 * one run writes. Shard I of N holds the slots k with k % N == I in slot
 * order; the merge reads the demos slot by slot and writes them through the
 * collection's own writer (sim_h5.c), so the bytes are a single run's. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/sim_h5.h"

/* the parts in shard order, checked to be the shards of one collection */
static hearth_status order_parts(sim_h5_in *in, int n, sim_h5_in **by_index, hearth_err *err) {
  const sim_h5_shard *s0 = &in[0].shard;
  if (n != s0->count)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "sim merge: %d file(s) given, but %s is shard %d of %d: give all %d", n,
                          in[0].path, s0->index, s0->count, s0->count);
  for (int i = 0; i < n; i++) by_index[i] = NULL;
  for (int i = 0; i < n; i++) {
    const sim_h5_shard *s = &in[i].shard;
    if (s->count != s0->count || s->layouts != s0->layouts)
      return hearth_err_set(
          err, HEARTH_E_ARG,
          "sim merge: %s is shard %d/%d of %lld layouts, %s shard %d/%d of %lld: not one collection",
          in[i].path, s->index, s->count, s->layouts, in[0].path, s0->index, s0->count,
          s0->layouts);
    for (int k = 0; k < SIM_H5_NKEYS; k++)
      if (strcmp(in[i].meta.str[k], in[0].meta.str[k]) != 0)
        return hearth_err_set(
            err, HEARTH_E_ARG,
            "sim merge: %s and %s differ in data@%s: not shards of one collection (task, seed, "
            "size, assets, renderer and split must agree)",
            in[0].path, in[i].path, sim_h5_key_names[k]);
    if (by_index[s->index])
      return hearth_err_set(err, HEARTH_E_ARG, "sim merge: %s and %s are both shard %d/%d",
                            by_index[s->index]->path, in[i].path, s->index, s->count);
    by_index[s->index] = &in[i];
  }
  return HEARTH_OK;
}

/* demos per slot (1: a split collection's file, 2: both instructions),
 * the same for every part */
static hearth_status demos_per_slot(sim_h5_in *const *part, int n, long long layouts, int *dps,
                                    hearth_err *err) {
  *dps = 0;
  for (int i = 0; i < n; i++) {
    long long slots = (layouts - i + n - 1) / n;
    int d = part[i]->ndemo == slots ? 1 : part[i]->ndemo == 2 * slots ? 2 : 0;
    if (!d || (*dps && d != *dps))
      return hearth_err_set(
          err, HEARTH_E_PARSE,
          "sim merge: %s: %d demos for its %lld slot(s) of %lld layouts; expected %lld or %lld%s",
          part[i]->path, part[i]->ndemo, slots, layouts, slots, 2 * slots,
          *dps ? " like the other parts" : "");
    *dps = d;
  }
  return HEARTH_OK;
}

hearth_status hearth_sim_merge(const char *out_path, const char *const *parts, int n_parts,
                               int *n_demos, hearth_err *err) {
  if (n_demos) *n_demos = 0;
  if (!out_path || !parts || n_parts < 1 || n_parts > HEARTH_SIM_MAX_LAYOUTS)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "sim merge: expected an output path and 1..%d part files",
                          HEARTH_SIM_MAX_LAYOUTS);
  sim_h5_in *in = calloc((size_t)n_parts, sizeof *in);
  sim_h5_in **part = calloc((size_t)n_parts, sizeof *part);
  if (!in || !part) {
    free(in), free(part);
    return hearth_err_set(err, HEARTH_E_NOMEM, "sim merge: out of memory");
  }
  for (int i = 0; i < n_parts; i++) in[i].f = in[i].data = -1;
  hearth_status st = HEARTH_OK;
  for (int i = 0; i < n_parts && !st; i++) {
    st = sim_h5_open(&in[i], parts[i], err);
    if (!st && in[i].shard.count == 0)
      st = hearth_err_set(
          err, HEARTH_E_ARG,
          "sim merge: %s has no data@hearth_shard: not written by `hearth sim collect --shard I/N`",
          parts[i]);
  }
  if (!st) st = order_parts(in, n_parts, part, err);
  int dps = 0;
  long long layouts = n_parts ? in[0].shard.layouts : 0;
  if (!st) st = demos_per_slot(part, n_parts, layouts, &dps, err);
  sim_h5_out out = {.f = -1, .data = -1};
  if (!st) st = sim_h5_create(&out, out_path, err);
  sim_demo b = {0};
  for (long long k = 0; k < layouts && !st; k++) {
    sim_h5_in *p = part[k % n_parts];
    long long slot = k / n_parts;
    for (int d = 0; d < dps && !st; d++) {
      char *instr = NULL, *model = NULL;
      int S = 0, idx = (int)(slot * dps + d);
      st = sim_h5_read_demo(p, idx, &b, &S, &instr, &model, err);
      if (!st && b.layout % (2u * HEARTH_SIM_MAX_LAYOUTS) != (uint64_t)k)
        st = hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: data/demo_%d: layout %llu does not belong to slot %lld", p->path,
                            idx, (unsigned long long)b.layout, k);
      if (!st) st = sim_h5_add_demo(&out, &b, S, instr, model, err);
      free(instr), free(model);
    }
  }
  sim_demo_free(&b);
  if (!st) {
    int written = out.ndemo;
    st = sim_h5_finish(&out, &part[0]->meta, NULL, err);
    if (!st && n_demos) *n_demos = written;
  } else {
    sim_h5_abort(&out);
  }
  for (int i = 0; i < n_parts; i++) sim_h5_close(&in[i]);
  free(in), free(part);
  return st;
}
