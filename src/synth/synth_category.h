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

/* ---- shape parameters ---------------------------------------------------- */

/* An instance's dimensions (metres unless noted), drawn by its steps. */
typedef enum synth_dim {
  D_R,       /* radius: top outer radius, body radius, ear-cup radius */
  D_R2,      /* second radius: vessel bottom, bottle neck */
  D_H,       /* height of the body; slab: thickness */
  D_T,       /* wall thickness; kettle: base height; headset: cup thickness */
  D_T2,      /* vessel: bottom thickness */
  D_E,       /* slab: edge round radius */
  D_RC,      /* slab: corner radius in plan */
  D_W,       /* slab: width (x); headset: distance between the cups */
  D_L,       /* slab: length (y) */
  D_A,       /* handle or band: half-width */
  D_C,       /* handle or band: half-thickness */
  D_REACH,   /* handle: how far it stands out */
  D_FILL,    /* liquid line, a fraction (see synth_fill) */
  D_ZSPLIT,  /* slab: height of the seam between the lower and upper side (0: none) */
  D_BULGE,   /* slab: how far the top face domes up (part of D_H) */
  D_VARIANT, /* 1: the instance's alternative look (synth_slot.style[1]; vessel lid) */
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

/* ---- materials ----------------------------------------------------------- */

/* Albedo styles: indices of synth_materials. */
enum {
  S_PLAIN,
  S_GLAZE,
  S_UNGLAZED,
  S_CAN_LABEL,
  S_ALU,
  S_ALU_TOP,
  S_CLEAR,
  S_BOTTLE_LABEL,
  S_CAP,
  S_PEEL,
  S_PEEL_TOP,
  S_SCREEN,
  S_FRAME,
  S_PHONE_BACK,
  S_FOAM,
  S_PAD,
  S_STEEL,
  S_STEEL_DARK,
  S_BLACK,
  S_MOUSE_TOP,
  S_RUBBER,
  S_SLEEVE,
  S_LAPTOP_LID,
  S_LAPTOP_BASE,
  S_LEATHER,
  S_TISSUE_BOX,
  S_TISSUE_TOP,
  S_CASE,
  S_FABRIC,
  S_FABRIC_CHECK,
  S_BAG,
  S_BAG_ZIP,
  S_CUSHION_PAD,
  S_GLAZE_BAND,
  S_COUNT
};

/* where a material's colour starts */
typedef enum synth_base {
  BASE_NONE, /* the pattern paints it all */
  BASE_RGB,  /* rgb */
  BASE_SLOT, /* the instance's colour slot `slot` */
  BASE_MIX,  /* colour slot `slot` blended towards rgb by `mix` */
} synth_base;

/* what is drawn over the base and grain (the shader's code); x, y are the
 * island's native coordinates in metres */
typedef enum synth_pattern {
  PAT_NONE,
  PAT_CAN_LABEL,    /* rims, a band of slot 1, a logo block with white lettering, small print */
  PAT_ALU,          /* radially brushed metal of brightness `param`; `alt`: the opening tab */
  PAT_BOTTLE_LABEL, /* white edges, white print across the middle */
  PAT_RIBS,         /* grip ribs round a strip */
  PAT_PEEL,         /* peel pores; `alt`: the stem spot */
  PAT_SCREEN,       /* black glass, the lit display inside the bezel, the camera */
  PAT_FRAME,        /* metal tinted by slot 0 */
  PAT_CAMERA,       /* a phone's camera island */
  PAT_PORES,        /* foam pores */
  PAT_FIBRES,       /* scouring-pad fibres */
  PAT_BRUSHED,      /* linearly brushed metal of brightness `param` */
  PAT_MOUSE,        /* the buttons' split and the wheel */
  PAT_PRINT,        /* white print of line height `param` */
  PAT_LOGO,         /* a round logo in the middle */
  PAT_FEET,         /* four feet near the corners */
  PAT_STITCHES,     /* a stitched seam round the faces */
  PAT_FLOWERS,      /* blotches of slot 1 */
  PAT_OPENING,      /* white tissue in an oval opening */
  PAT_WEAVE,        /* fabric weave; `alt`: a check */
  PAT_ZIP,          /* a zip of slot 0 along the middle of a strip */
} synth_pattern;

/* The colour of a surface point: base, then a band round strips, then the
 * grain (fbm noise of cell grain_size metres) added, then the pattern. */
typedef struct synth_material {
  int stream; /* seeds the material's noise: texture seed + 977 * stream */
  synth_base base;
  double rgb[3];
  int slot;
  double mix;
  double band[3]; /* a band of slot 0 between heights band[0] and band[1] (fractions of a
                         strip), blended in by band[2]; band[2] = 0: none */
  double grain;   /* amplitude; 0: none */
  double grain_size;
  int grain_octaves;
  synth_pattern pattern;
  double param;
  int alt;
} synth_material;

extern const synth_material synth_materials[S_COUNT];

/* ---- shapes -------------------------------------------------------------- */

/* The shape builders (synth_objects.c); each names the slots it fills. */
typedef enum synth_shape {
  SHAPE_VESSEL,   /* open revolved vessel: wall, rim, inner wall, handle(s), lid */
  SHAPE_CAN,      /* drinks can: label, rolled rim, lid, domed bottom */
  SHAPE_BOTTLE,   /* bottle: body, label band, shoulder, neck, cap */
  SHAPE_SPHEROID, /* fruit: a bumpy spheroid with a stem end */
  SHAPE_KETTLE,   /* kettle on its base: body, domed lid and knob, handle, spout */
  SHAPE_SLAB,     /* rounded box, optionally split along the side and domed on top */
  SHAPE_HEADSET,  /* two ear cups with cushions and a head band */
  SHAPE_COUNT
} synth_shape;

/* A part of the surface and its material: style[0], or style[1] for an
 * instance drawn with D_VARIANT. Parts are numbered in slot order (a slot
 * naming an earlier slot's part joins it). */
typedef struct synth_slot {
  const char *part;
  int style[2];
} synth_slot;
#define SYNTH_MAX_SLOTS 8

/* the slots of each shape */
enum {
  VESSEL_BODY,
  VESSEL_BOTTOM,
  VESSEL_RIM,
  VESSEL_INNER,
  VESSEL_HANDLE,
  VESSEL_LID,
  VESSEL_KNOB,
  VESSEL_SLOTS
};
enum { CAN_BODY, CAN_RIM, CAN_LID, CAN_DOME, CAN_FOOT, CAN_SLOTS };
enum { BOTTLE_BODY, BOTTLE_LABEL, BOTTLE_NECK, BOTTLE_CAP, BOTTLE_BOTTOM, BOTTLE_SLOTS };
enum { SPHEROID_PEEL, SPHEROID_STEM, SPHEROID_SLOTS };
enum {
  KETTLE_BASE,
  KETTLE_BODY,
  KETTLE_LID,
  KETTLE_KNOB,
  KETTLE_HANDLE,
  KETTLE_SPOUT,
  KETTLE_SLOTS
};
enum { SLAB_BOTTOM, SLAB_SIDE, SLAB_UPPER, SLAB_TOP, SLAB_SLOTS }; /* upper: side above D_ZSPLIT */
enum { HEADSET_CUP, HEADSET_CUSHION, HEADSET_BAND, HEADSET_SLOTS };

/* SHAPE_VESSEL: wall from radius D_R2 at the bottom to D_R at height D_H,
 * wall D_T, bottom D_T2 */
typedef struct synth_vessel {
  double margin;      /* the outline is sampled for radius D_R + margin */
  double foot;        /* radius of the round at the outer bottom edge */
  int foot_steps;     /* its fewest segments */
  double inner_round; /* radius of the round at the inner bottom edge */
  /* handles: 0: one mug handle at azimuth 0, ends at heights mug[0] * D_H and
   * mug[1] * D_H, standing out mug[2] * D_REACH; 1: two lugs at azimuths 0
   * and pi, centred lug[0] below the rim, lug[1] high each way, standing
   * out D_REACH */
  int lugs;
  double mug[3], lug[2];
  int lid; /* a domed lid with a knob when D_VARIANT is drawn */
} synth_vessel;

/* ---- temperature fields -------------------------------------------------- */

/* How a state's temperatures spread over the object (synth_fields.c). T0..
 * are the state's drawn temperatures (degC, or degC above ambient where
 * marked +amb), in the order below. */
typedef enum synth_field_model {
  FIELD_TOP_COOLER,    /* hot: T0 at the bottom, T1 cooler at the top */
  FIELD_CUP,           /* hot drink: T0 below the liquid line, T1 rim, handle T2 at the body to
                          T3 at its far end, T4 line width (m), T5 bottom cooler by */
  FIELD_KETTLE,        /* T0 below the line, T1 above, T2 lid, T3 handle, T4 base, T5 spout,
                          T6 line width (m) */
  FIELD_POT,           /* T0 below the line, T1 rim, handle T2 to T3, T4 lid, T5 line width (m) */
  FIELD_SPONGE,        /* T0, moist patches T1 cooler, the pad T2 cooler */
  FIELD_PHONE,         /* T0 edges, T1 battery on the back, T2 SoC, T3 screen */
  FIELD_CHILLED,       /* iced: T0 at the bottom rising to T1 at the top */
  FIELD_CHILLED_FRUIT, /* iced: T0 at the bottom, T1 more at the top */
  FIELD_WARM,          /* warm: +amb T0 at the bottom, 0.8 T0 at the top */
  FIELD_LAPTOP,        /* warm: +amb T0 more under the CPU, T1 the base, T2 the lid */
  FIELD_USED,          /* used: +amb 0.4 T0, up to T0 in blobs where it was handled (T1 is
                          drawn for the variants below) */
  FIELD_USED_CUSHION,  /* FIELD_USED, with cushions at +amb T1 */
  FIELD_USED_GRIP,     /* FIELD_USED, with the shell +amb T0 at the front to T1 under the palm */
  FIELD_MODELS
} synth_field_model;

#define SYNTH_MAX_TEMPS 7

/* one state: its model and the ranges its temperatures are drawn from */
typedef struct synth_temps {
  synth_field_model model;
  int n;
  double range[SYNTH_MAX_TEMPS][2];
} synth_temps;

/* the states other than neutral (ambient with small smooth variations) */
typedef struct synth_field_spec {
  int stream; /* random stream of the draws (with the state): fixed, part of the output */
  synth_temps hot, warm, iced, used;
} synth_field_spec;

/* the field of names outside the table (a given mesh's category) */
extern const synth_field_spec synth_field_other;

/* ---- categories ---------------------------------------------------------- */

typedef struct synth_category {
  const char *name;
  const char *second_state; /* captured besides "neutral" by default; NULL: none */
  synth_draw draw[SYNTH_MAX_DRAWS];
  synth_shape shape;
  synth_slot slots[SYNTH_MAX_SLOTS]; /* indexed by the shape's slot enum */
  synth_vessel vessel;               /* SHAPE_VESSEL only */
  synth_fill fill;
  double wrapped_fill; /* fill level of a given mesh put under this category */
  synth_field_spec field;
} synth_category;

extern const synth_category synth_categories[SYNTH_N_CATEGORIES];

/* index in synth_categories, or -1 (name NULL or unknown) */
int synth_category_index(const char *name);
/* the entry, or NULL */
const synth_category *synth_category_find(const char *name);

#endif
