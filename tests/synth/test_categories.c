/* The virtual rig's category table (synth_categories.c): one entry for each
 * of the dataset's categories, unique names, draws that only read what was
 * drawn before, dimensions, colours, materials and temperatures in sane
 * ranges, and objects whose parts are the entry's slots. */
#include <stdint.h>
#include <string.h>

#include "hearth/dataset.h"
#include "synth/synth_category.h"
#include "synth/synth_object.h"
#include "test_util.h"

/* slots each shape fills (the vessel's last two only with a lid) */
static const int k_slots[SHAPE_COUNT] = {
    [SHAPE_VESSEL] = VESSEL_SLOTS,     [SHAPE_CAN] = CAN_SLOTS,       [SHAPE_BOTTLE] = BOTTLE_SLOTS,
    [SHAPE_SPHEROID] = SPHEROID_SLOTS, [SHAPE_KETTLE] = KETTLE_SLOTS, [SHAPE_SLAB] = SLAB_SLOTS,
    [SHAPE_HEADSET] = HEADSET_SLOTS};

/* dimensions each shape reads */
static const synth_dim k_needs[SHAPE_COUNT][9] =
    {[SHAPE_VESSEL] = {D_R, D_R2, D_H, D_T, D_T2, D_A, D_C, D_REACH, D_COUNT},
     [SHAPE_CAN] = {D_R, D_H, D_COUNT},
     [SHAPE_BOTTLE] = {D_R, D_H, D_R2, D_COUNT},
     [SHAPE_SPHEROID] = {D_R, D_H, D_COUNT},
     [SHAPE_KETTLE] = {D_R, D_H, D_T, D_REACH, D_COUNT},
     [SHAPE_SLAB] = {D_W, D_L, D_H, D_RC, D_E, D_COUNT},
     [SHAPE_HEADSET] = {D_R, D_T, D_W, D_A, D_C, D_COUNT}};

/* temperatures each model draws, and the state it belongs to */
static const struct {
  int n;
  const char *state;
} k_models[FIELD_MODELS] = {[FIELD_TOP_COOLER] = {2, "hot"}, [FIELD_CUP] = {6, "hot"},
                            [FIELD_KETTLE] = {7, "hot"},     [FIELD_POT] = {6, "hot"},
                            [FIELD_SPONGE] = {3, "hot"},     [FIELD_PHONE] = {4, "hot warm"},
                            [FIELD_CHILLED] = {2, "iced"},   [FIELD_CHILLED_FRUIT] = {2, "iced"},
                            [FIELD_WARM] = {1, "warm"},      [FIELD_LAPTOP] = {3, "warm"},
                            [FIELD_USED] = {2, "used"},      [FIELD_USED_CUSHION] = {2, "used"},
                            [FIELD_USED_GRIP] = {2, "used"}};

/* the steps' structure: ops, indices, ranges, reads after writes */
static void check_steps(const synth_category *c, int drawn[D_COUNT]) {
  memset(drawn, 0, D_COUNT * sizeof *drawn);
  int ended = 0;
  for (int i = 0; i < SYNTH_MAX_DRAWS; i++) {
    const synth_draw *st = &c->draw[i];
    if (st->op == DRAW_END) {
      ended = 1;
      continue;
    }
    CHECK_MSG(!ended, "%s: step %d after the end of the list", c->name, i);
    CHECK_MSG(st->op > DRAW_END && st->op <= DRAW_COLOUR, "%s: step %d op %d", c->name, i, st->op);
    if (st->op == DRAW_COLOUR) {
      CHECK_MSG(st->dst >= 0 && st->dst < 4, "%s: colour slot %d", c->name, st->dst);
      CHECK_MSG(st->src >= 0 && st->src < PAL_COUNT, "%s: palette %d", c->name, st->src);
      if (st->src >= 0 && st->src < PAL_COUNT)
        CHECK_MSG(st->k >= 1 && st->k <= synth_palettes[st->src].n && st->k == (int)st->k,
                  "%s: %g colours of a palette of %d", c->name, st->k, synth_palettes[st->src].n);
      continue;
    }
    CHECK_MSG(st->dst >= 0 && st->dst < D_COUNT, "%s: step %d writes dimension %d", c->name, i,
              st->dst);
    if (st->dst < 0 || st->dst >= D_COUNT) continue;
    if (st->op == DRAW_SCALED || st->op == DRAW_OFFSET || st->op == DRAW_TIMES ||
        st->op == DRAW_MINUS)
      CHECK_MSG(st->src >= 0 && st->src < D_COUNT && drawn[st->src],
                "%s: step %d reads dimension %d before it is drawn", c->name, i, st->src);
    if (st->op == DRAW_RANGE || st->op == DRAW_SCALED || st->op == DRAW_OFFSET)
      CHECK_MSG(st->lo < st->hi, "%s: step %d range [%g, %g]", c->name, i, st->lo, st->hi);
    if (st->op == DRAW_FLAG)
      CHECK_MSG(st->k > 0 && st->k < 1, "%s: flag probability %g", c->name, st->k);
    CHECK_MSG(!drawn[st->dst], "%s: dimension %d drawn twice", c->name, st->dst);
    drawn[st->dst] = 1;
  }
}

/* one instance's dimensions: sample 0 with every draw at the low end of
 * its range, 1 at the high end, others at pseudo-random fractions */
static void sample_dims(const synth_category *c, uint64_t sample, double d[D_COUNT]) {
  uint64_t u = sample;
  memset(d, 0, D_COUNT * sizeof *d);
  for (int i = 0; i < SYNTH_MAX_DRAWS && c->draw[i].op != DRAW_END; i++) {
    const synth_draw *st = &c->draw[i];
    if (st->op == DRAW_COLOUR || st->dst < 0 || st->dst >= D_COUNT ||
        (st->src < 0 || st->src >= D_COUNT))
      continue;
    u = u * 6364136223846793005ULL + 1442695040888963407ULL;
    double f = sample == 0 ? 0 : sample == 1 ? 1 : (double)(u >> 11) / 9007199254740992.0;
    double x = st->lo + (st->hi - st->lo) * f, s = d[st->src];
    switch (st->op) {
      case DRAW_RANGE: d[st->dst] = x; break;
      case DRAW_SCALED: d[st->dst] = st->k * s * x; break;
      case DRAW_OFFSET: d[st->dst] = s + x; break;
      case DRAW_CONST: d[st->dst] = st->k; break;
      case DRAW_TIMES: d[st->dst] = s * st->k; break;
      case DRAW_MINUS: d[st->dst] = s - st->k; break;
      case DRAW_FLAG: d[st->dst] = f < st->k || sample == 1; break;
      default: break;
    }
  }
}

/* what the shape needs of one instance's dimensions */
static void check_dims(const synth_category *c, const double d[D_COUNT], const int drawn[D_COUNT]) {
  for (int k = 0; k < D_COUNT; k++)
    CHECK_MSG(d[k] >= 0 && d[k] <= (k == D_FILL || k == D_VARIANT ? 1 : 0.6),
              "%s: dimension %d = %g", c->name, k, d[k]);
  CHECK_MSG(!drawn[D_FILL] || (d[D_FILL] > 0 && d[D_FILL] < 1), "%s: fill %g", c->name, d[D_FILL]);
  for (const synth_dim *n = k_needs[c->shape]; *n != D_COUNT; n++)
    CHECK_MSG(drawn[*n] && d[*n] > 0, "%s: dimension %d = %g", c->name, *n, d[*n]);
  if (c->shape == SHAPE_SLAB) {
    double side = d[D_H] - d[D_BULGE];
    CHECK_MSG(2 * d[D_RC] <= fmin(d[D_W], d[D_L]) && d[D_RC] > d[D_E],
              "%s: corner radius %g for %g x %g, edge %g", c->name, d[D_RC], d[D_W], d[D_L],
              d[D_E]);
    CHECK_MSG(2 * d[D_E] < side, "%s: edge rounds %g on a side %g high", c->name, d[D_E], side);
    /* a seam the builder would not cut is a mistake in the table */
    CHECK_MSG(d[D_ZSPLIT] == 0 || (d[D_ZSPLIT] > d[D_E] && d[D_ZSPLIT] < side - d[D_E]),
              "%s: seam at %g on a side %g high", c->name, d[D_ZSPLIT], side);
  }
  if (c->shape == SHAPE_VESSEL)
    CHECK_MSG(c->vessel.foot > 0 && c->vessel.inner_round > 0 && c->vessel.foot_steps >= 2 &&
                  d[D_T2] + c->vessel.inner_round < d[D_H] && d[D_T] < d[D_R2] &&
                  d[D_R2] <= d[D_R] && c->vessel.foot < d[D_R2],
              "%s: vessel parameters", c->name);
}

static void check_entry(int ci) {
  const synth_category *c = &synth_categories[ci];
  CHECK_MSG(synth_category_index(c->name) == ci, "%s: found at %d", c->name,
            synth_category_index(c->name));
  if (c->second_state)
    CHECK_MSG(hearth_state_valid(c->second_state) && strcmp(c->second_state, "neutral") != 0,
              "%s: second state %s", c->name, c->second_state);

  /* dimensions: metres up to 0.6, fractions below 1, what the shape reads */
  int drawn[D_COUNT];
  check_steps(c, drawn);
  CHECK_MSG(c->wrapped_fill >= 0 && c->wrapped_fill < 1, "%s: wrapped fill %g", c->name,
            c->wrapped_fill);
  CHECK_MSG(c->fill == FILL_DRAWN || (c->fill <= FILL_ABOVE_BASE && drawn[D_FILL]),
            "%s: fill rule %d without a drawn fill", c->name, c->fill);
  CHECK_MSG(c->shape >= 0 && c->shape < SHAPE_COUNT, "%s: shape %d", c->name, c->shape);
  if (c->shape < 0 || c->shape >= SHAPE_COUNT) return;
  /* the first sample that fails is enough */
  int failures = g_test_failures;
  for (uint64_t u = 0; u < 64 && g_test_failures == failures; u++) {
    double d[D_COUNT];
    sample_dims(c, u, d);
    check_dims(c, d, drawn);
  }

  /* slots: the shape's all named, with valid styles; none beyond */
  for (int k = 0; k < SYNTH_MAX_SLOTS; k++) {
    const synth_slot *sl = &c->slots[k];
    int used =
        k < k_slots[c->shape] && !(c->shape == SHAPE_VESSEL && k >= VESSEL_LID && !c->vessel.lid);
    if (!used) {
      CHECK_MSG(!sl->part, "%s: slot %d (%s) is not used by its shape", c->name, k, sl->part);
      continue;
    }
    CHECK_MSG(sl->part && *sl->part, "%s: slot %d has no part", c->name, k);
    for (int v = 0; v < 2; v++)
      CHECK_MSG(sl->style[v] >= 0 && sl->style[v] < S_COUNT, "%s: slot %d style %d", c->name, k,
                sl->style[v]);
  }

  /* fields: a model of the right state for each, with its temperatures */
  const synth_field_spec *f = &c->field;
  CHECK_MSG(f->stream >= 0 && f->stream <= 11, "%s: field stream %d", c->name, f->stream);
  const synth_temps *states[4] = {&f->hot, &f->warm, &f->iced, &f->used};
  static const char *const names[4] = {"hot", "warm", "iced", "used"};
  for (int s = 0; s < 4; s++) {
    const synth_temps *t = states[s];
    CHECK_MSG(t->model >= 0 && t->model < FIELD_MODELS, "%s/%s: model %d", c->name, names[s],
              t->model);
    if (t->model < 0 || t->model >= FIELD_MODELS) continue;
    CHECK_MSG(strstr(k_models[t->model].state, names[s]) != NULL, "%s/%s: a %s model", c->name,
              names[s], k_models[t->model].state);
    CHECK_MSG(t->n == k_models[t->model].n && t->n <= SYNTH_MAX_TEMPS,
              "%s/%s: %d temperatures, the model takes %d", c->name, names[s], t->n,
              k_models[t->model].n);
    for (int k = 0; k < t->n && k < SYNTH_MAX_TEMPS; k++)
      CHECK_MSG(t->range[k][0] < t->range[k][1] && t->range[k][0] > 0 && t->range[k][1] < 100,
                "%s/%s: T%d in [%g, %g]", c->name, names[s], k, t->range[k][0], t->range[k][1]);
  }
}

/* the object's parts are the distinct slot parts, in slot order */
static void check_parts(const synth_category *c) {
  hearth_err err = {0};
  for (uint64_t seed = 1; seed <= 4; seed++) {
    synth_object o;
    CHECK_OK(synth_object_make(c->name, seed, 1500, 16, &o, &err), &err);
    if (err.status) return;
    const char *want[SYNTH_MAX_SLOTS];
    int n = 0;
    for (int k = 0; k < SYNTH_MAX_SLOTS && c->slots[k].part; k++) {
      int seen = 0;
      for (int j = 0; j < n; j++) seen |= strcmp(want[j], c->slots[k].part) == 0;
      if (!seen) want[n++] = c->slots[k].part;
    }
    /* a vessel's lid comes with its variant only */
    int lid = c->shape == SHAPE_VESSEL && c->vessel.lid;
    CHECK_MSG(o.n_parts == n || (lid && o.n_parts == n - 1), "%s: %d parts, %d slot parts", c->name,
              o.n_parts, n);
    for (int k = 0; k < o.n_parts && k < n; k++)
      CHECK_MSG(strcmp(o.part_names[k], want[k]) == 0, "%s: part %d is %s, slot part %s", c->name,
                k, o.part_names[k], want[k]);
    synth_object_free(&o);
  }
}

static void check_materials(void) {
  for (int m = 0; m < S_COUNT; m++) {
    const synth_material *mt = &synth_materials[m];
    CHECK_MSG(mt->stream >= 0 && mt->stream < S_COUNT, "material %d: stream %d", m, mt->stream);
    CHECK_MSG(mt->base >= BASE_NONE && mt->base <= BASE_MIX, "material %d: base %d", m, mt->base);
    CHECK_MSG(mt->base != BASE_NONE || mt->pattern != PAT_NONE, "material %d paints nothing", m);
    CHECK_MSG(mt->slot >= 0 && mt->slot < 4, "material %d: slot %d", m, mt->slot);
    for (int k = 0; k < 3; k++)
      CHECK_MSG(mt->rgb[k] >= 0 && mt->rgb[k] <= 1, "material %d: rgb %g", m, mt->rgb[k]);
    CHECK_MSG(mt->mix >= 0 && mt->mix <= 1, "material %d: mix %g", m, mt->mix);
    CHECK_MSG(mt->band[2] == 0 || (mt->band[0] < mt->band[1] && mt->band[2] <= 1),
              "material %d: band", m);
    CHECK_MSG(mt->grain == 0 ||
                  (mt->grain_size > 0 && mt->grain_octaves >= 1 && fabs(mt->grain) < 0.2),
              "material %d: grain %g of %g m, %d octaves", m, mt->grain, mt->grain_size,
              mt->grain_octaves);
    CHECK_MSG(mt->pattern >= PAT_NONE && mt->pattern <= PAT_ZIP, "material %d: pattern %d", m,
              mt->pattern);
  }
  /* two materials share a stream only where one is the other with a band */
  for (int a = 0; a < S_COUNT; a++)
    for (int b = a + 1; b < S_COUNT; b++)
      if (synth_materials[a].stream == synth_materials[b].stream)
        CHECK_MSG((synth_materials[a].band[2] > 0) != (synth_materials[b].band[2] > 0),
                  "materials %d and %d share stream %d", a, b, synth_materials[a].stream);
  for (int p = 0; p < PAL_COUNT; p++) {
    CHECK(synth_palettes[p].n >= 4 && synth_palettes[p].rgb != NULL);
    for (int k = 0; k < synth_palettes[p].n; k++)
      for (int m = 0; m < 3; m++)
        CHECK(synth_palettes[p].rgb[k][m] >= 0 && synth_palettes[p].rgb[k][m] <= 1);
  }
}

int main(void) {
  /* one entry per dataset category, and no other */
  CHECK(SYNTH_N_CATEGORIES == 18);
  for (int i = 0; i < 18; i++) {
    int hits = 0;
    for (int c = 0; c < SYNTH_N_CATEGORIES; c++)
      hits +=
          synth_categories[c].name && strcmp(synth_categories[c].name, hearth_categories[i]) == 0;
    CHECK_MSG(hits == 1, "dataset category %s: %d entries", hearth_categories[i], hits);
  }
  for (int c = 0; c < SYNTH_N_CATEGORIES; c++) {
    CHECK_MSG(synth_categories[c].name && hearth_category_valid(synth_categories[c].name),
              "entry %d: %s is not a dataset category", c,
              synth_categories[c].name ? synth_categories[c].name : "(null)");
    for (int d = c + 1; d < SYNTH_N_CATEGORIES; d++)
      CHECK_MSG(strcmp(synth_categories[c].name, synth_categories[d].name) != 0,
                "entries %d and %d are both %s", c, d, synth_categories[c].name);
  }

  /* the listing and the default states come from the table, in its order */
  const char *names[SYNTH_N_CATEGORIES + 4];
  CHECK(synth_object_categories(names, SYNTH_N_CATEGORIES + 4) == SYNTH_N_CATEGORIES);
  CHECK(synth_object_categories(NULL, 0) == SYNTH_N_CATEGORIES);
  for (int c = 0; c < SYNTH_N_CATEGORIES; c++) {
    CHECK(names[c] == synth_categories[c].name);
    const char *st[3];
    size_t n = synth_category_states(names[c], st, 3);
    CHECK(n == (synth_categories[c].second_state ? 2u : 1u) && strcmp(st[0], "neutral") == 0);
    if (n == 2) CHECK(strcmp(st[1], synth_categories[c].second_state) == 0);
  }
  CHECK(synth_category_index("teapot") == -1 && synth_category_index(NULL) == -1);
  CHECK(synth_category_find("teapot") == NULL);

  /* the stream of each category's own field is its own */
  for (int c = 0; c < SYNTH_N_CATEGORIES; c++)
    for (int d = c + 1; d < SYNTH_N_CATEGORIES; d++)
      if (synth_categories[c].field.stream != 11)
        CHECK_MSG(synth_categories[c].field.stream != synth_categories[d].field.stream,
                  "%s and %s share field stream %d", synth_categories[c].name,
                  synth_categories[d].name, synth_categories[c].field.stream);
  CHECK(synth_field_other.stream == 11);

  for (int c = 0; c < SYNTH_N_CATEGORIES; c++) {
    check_entry(c);
    check_parts(&synth_categories[c]);
  }
  check_materials();
  TEST_MAIN_END();
}
