/* The virtual rig's object categories (see synth_category.h). */
#include <string.h>

#include "synth/synth_category.h"
#include "synth/synth_object.h"

const synth_category synth_categories[SYNTH_N_CATEGORIES] = {
    {.name = "cup", .second_state = "hot", .fill = FILL_DRAWN, .wrapped_fill = 0.8,
     .field_stream = 0},
    {.name = "canned_drink", .second_state = "iced", .fill = FILL_DRAWN, .field_stream = 1},
    {.name = "bottled_drink", .second_state = "iced", .fill = FILL_DRAWN, .field_stream = 2},
    {.name = "orange", .second_state = "iced", .fill = FILL_DRAWN, .field_stream = 3},
    {.name = "smartphone", .second_state = "warm", .fill = FILL_DRAWN, .field_stream = 4},
    {.name = "sponge", .second_state = "hot", .fill = FILL_DRAWN, .field_stream = 5},
    {.name = "electric_kettle", .second_state = "hot", .fill = FILL_ABOVE_BASE,
     .wrapped_fill = 0.6, .field_stream = 6},
    {.name = "pot", .second_state = "hot", .fill = FILL_DEPTH, .wrapped_fill = 0.6,
     .field_stream = 7},
    {.name = "mouse", .second_state = "used", .fill = FILL_DRAWN, .field_stream = 8},
    {.name = "eraser", .fill = FILL_DRAWN, .field_stream = SYNTH_FIELD_STREAM_OTHER},
    {.name = "laptop", .second_state = "warm", .fill = FILL_DRAWN, .field_stream = 9},
    {.name = "wallet", .fill = FILL_DRAWN, .field_stream = SYNTH_FIELD_STREAM_OTHER},
    {.name = "tissue", .fill = FILL_DRAWN, .field_stream = SYNTH_FIELD_STREAM_OTHER},
    {.name = "glasses_case", .fill = FILL_DRAWN, .field_stream = SYNTH_FIELD_STREAM_OTHER},
    {.name = "pillow", .fill = FILL_DRAWN, .field_stream = SYNTH_FIELD_STREAM_OTHER},
    {.name = "cushion", .fill = FILL_DRAWN, .field_stream = SYNTH_FIELD_STREAM_OTHER},
    {.name = "storage_bag", .fill = FILL_DRAWN, .field_stream = SYNTH_FIELD_STREAM_OTHER},
    {.name = "headset", .second_state = "used", .fill = FILL_DRAWN, .field_stream = 10},
};

int synth_category_index(const char *name) {
  if (!name) return -1;
  for (int c = 0; c < SYNTH_N_CATEGORIES; c++)
    if (strcmp(name, synth_categories[c].name) == 0) return c;
  return -1;
}

const synth_category *synth_category_find(const char *name) {
  int c = synth_category_index(name);
  return c < 0 ? NULL : &synth_categories[c];
}

size_t synth_object_categories(const char **names, size_t max) {
  for (size_t c = 0; names && c < SYNTH_N_CATEGORIES && c < max; c++)
    names[c] = synth_categories[c].name;
  return SYNTH_N_CATEGORIES;
}

size_t synth_category_states(const char *category, const char **states, size_t max) {
  const synth_category *c = synth_category_find(category);
  if (states && max > 0) states[0] = "neutral";
  if (!c || !c->second_state) return 1;
  if (states && max > 1) states[1] = c->second_state;
  return 2;
}
