/* Private to the virtual rig: its procedural object categories as one table
 * (synth_categories.c), read by the object maker (synth_objects.c), the
 * temperature fields (synth_fields.c) and, through synth_object_categories,
 * the release writer and the command line.
 *
 * One entry per category, in one order. The order is part of the output:
 * an entry's index seeds the random draws of its instances' shapes. */
#ifndef HEARTH_SYNTH_CATEGORY_H
#define HEARTH_SYNTH_CATEGORY_H

#include <stddef.h>

#define SYNTH_N_CATEGORIES 18

/* how an instance's liquid line (synth_object.fill_level) follows from its
 * drawn dimensions */
typedef enum synth_fill {
  FILL_DRAWN,      /* the drawn fraction itself (0: no liquid) */
  FILL_DEPTH,      /* drawn fraction of the body height, over the object's height */
  FILL_ABOVE_BASE, /* the same, standing on a base of its own height */
} synth_fill;

typedef struct synth_category {
  const char *name;
  const char *second_state; /* captured besides "neutral" by default; NULL: none */
  synth_fill fill;
  double wrapped_fill;      /* fill level of a given mesh put under this category */
  /* the random stream of the temperature draws (with the state); categories
   * without a field of their own share stream 11 */
  int field_stream;
} synth_category;

extern const synth_category synth_categories[SYNTH_N_CATEGORIES];

/* index in synth_categories, or -1 (name NULL or unknown) */
int synth_category_index(const char *name);
/* the entry, or NULL */
const synth_category *synth_category_find(const char *name);
/* the stream for categories without a field of their own (also for names
 * outside the table) */
#define SYNTH_FIELD_STREAM_OTHER 11

#endif
