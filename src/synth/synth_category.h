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

/* ---- shape parameters ------------------------------------------------------ */

/* An instance's dimensions (metres unless noted), drawn by its steps. */
typedef enum synth_dim {
  D_R,       /* radius: top outer radius, body radius, ear-cup radius */
  D_R2,      /* second radius: cup bottom, bottle neck */
  D_H,       /* height; slab: thickness */
  D_H2,      /* second height: kettle and pot body, sponge foam, laptop base */
  D_T,       /* wall thickness; kettle: base height; headset: cup thickness */
  D_T2,      /* bottom thickness */
  D_E,       /* slab: edge round radius */
  D_RC,      /* slab: corner radius in plan */
  D_W,       /* slab: width (x); headset: distance between the cups */
  D_L,       /* slab: length (y) */
  D_A,       /* handle or band: half-width */
  D_C,       /* handle or band: half-thickness */
  D_REACH,   /* handle: how far it stands out */
  D_FILL,    /* liquid line, a fraction (see synth_fill) */
  D_VARIANT, /* 1: the instance's alternative look (cup band, kettle steel, pot lid) */
  D_COUNT
} synth_dim;

/* Colour palettes an instance picks from (synth_palettes). */
typedef enum synth_palette_id { PAL_VIVID, PAL_DARK, PAL_PASTEL, PAL_COUNT } synth_palette_id;
typedef struct synth_palette {
  const double (*rgb)[3];
  int n;
} synth_palette;
extern const synth_palette synth_palettes[PAL_COUNT];

/* One draw of an instance's parameters; u is a uniform draw in [lo, hi]. The
 * steps run in order (the order of the random draws is part of the output)
 * after the texture seed and four colours from PAL_VIVID. */
typedef enum synth_draw_op {
  DRAW_END,    /* no more steps */
  DRAW_RANGE,  /* d[dst] = u */
  DRAW_SCALED, /* d[dst] = k * d[src] * u */
  DRAW_OFFSET, /* d[dst] = d[src] + u */
  DRAW_CONST,  /* d[dst] = k */
  DRAW_TIMES,  /* d[dst] = d[src] * k */
  DRAW_MINUS,  /* d[dst] = d[src] - k */
  DRAW_FLAG,   /* d[dst] = 1 with probability k, else 0 */
  DRAW_COLOUR, /* colour slot dst (0..3) = one of the first k colours of palette src */
} synth_draw_op;

typedef struct synth_draw {
  synth_draw_op op;
  int dst, src;
  double k, lo, hi;
} synth_draw;

#define SYNTH_MAX_DRAWS 12

/* how an instance's liquid line (synth_object.fill_level) follows from its
 * drawn dimensions */
typedef enum synth_fill {
  FILL_DRAWN,      /* the drawn fraction itself (0: no liquid) */
  FILL_DEPTH,      /* drawn fraction of the body height, over the object's height */
  FILL_ABOVE_BASE, /* the same, standing on a base of its own height */
} synth_fill;

/* ---- categories ------------------------------------------------------------ */

typedef struct synth_category {
  const char *name;
  const char *second_state; /* captured besides "neutral" by default; NULL: none */
  synth_draw draw[SYNTH_MAX_DRAWS];
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
