/* The virtual rig's object categories (see synth_category.h). */
#include <string.h>

#include "synth/synth_category.h"
#include "synth/synth_object.h"

/* ---- palettes ------------------------------------------------------------ */

static const double k_vivid[8][3] = {{0.80, 0.10, 0.12}, {0.10, 0.30, 0.75}, {0.95, 0.75, 0.10},
                                     {0.10, 0.55, 0.25}, {0.55, 0.15, 0.55}, {0.95, 0.45, 0.10},
                                     {0.85, 0.85, 0.88}, {0.10, 0.10, 0.12}};
static const double k_dark[6][3] = {{0.08, 0.08, 0.09}, {0.20, 0.22, 0.25}, {0.12, 0.16, 0.30},
                                    {0.35, 0.18, 0.10}, {0.85, 0.85, 0.86}, {0.75, 0.60, 0.55}};
static const double k_pastel[6][3] = {{0.92, 0.90, 0.85}, {0.80, 0.86, 0.93}, {0.93, 0.82, 0.84},
                                      {0.82, 0.90, 0.80}, {0.95, 0.93, 0.78}, {0.70, 0.72, 0.75}};

const synth_palette synth_palettes[PAL_COUNT] =
    {[PAL_VIVID] = {k_vivid, 8}, [PAL_DARK] = {k_dark, 6}, [PAL_PASTEL] = {k_pastel, 6}};

/* ---- materials ----------------------------------------------------------- */

#define RGB(r, g, b) .base = BASE_RGB, .rgb = {r, g, b}
#define COL(k) .base = BASE_SLOT, .slot = k
#define GRAIN(amp) .grain = amp, .grain_size = 0.01, .grain_octaves = 3
#define FINE_GRAIN(amp) .grain = amp, .grain_size = 0.002, .grain_octaves = 2

/* The first number is the material's stream: fixed, it seeds the material's
 * noise (the banded glaze shares the glaze's). */
const synth_material synth_materials[S_COUNT] = {
    [S_PLAIN] = {0, RGB(0.94, 0.94, 0.93), GRAIN(0.02)},
    [S_GLAZE] = {1, RGB(0.93, 0.93, 0.91), GRAIN(0.015)},
    [S_GLAZE_BAND] = {1, RGB(0.93, 0.93, 0.91), .band = {0.55, 0.70, 0.85}, GRAIN(0.015)},
    [S_UNGLAZED] = {2, RGB(0.82, 0.76, 0.66), GRAIN(0.04)},
    [S_CAN_LABEL] = {3, COL(0), .pattern = PAT_CAN_LABEL},
    [S_ALU] = {4, .pattern = PAT_ALU, .param = 0.74},
    [S_ALU_TOP] = {5, .pattern = PAT_ALU, .param = 0.74, .alt = 1},
    [S_CLEAR] = {6, RGB(0.78, 0.86, 0.88), GRAIN(0.03)},
    [S_BOTTLE_LABEL] = {7, COL(0), .pattern = PAT_BOTTLE_LABEL},
    [S_CAP] = {8, COL(1), .pattern = PAT_RIBS},
    [S_PEEL] = {9, RGB(0.96, 0.55, 0.10), .pattern = PAT_PEEL},
    [S_PEEL_TOP] = {10, RGB(0.96, 0.55, 0.10), .pattern = PAT_PEEL, .alt = 1},
    [S_SCREEN] = {11, .pattern = PAT_SCREEN},
    [S_FRAME] = {12, .pattern = PAT_FRAME},
    [S_PHONE_BACK] = {13, COL(0), GRAIN(0.01), .pattern = PAT_CAMERA},
    [S_FOAM] = {14, RGB(0.97, 0.82, 0.22), .pattern = PAT_PORES},
    [S_PAD] = {15, RGB(0.12, 0.45, 0.18), .pattern = PAT_FIBRES},
    [S_STEEL] = {16, .pattern = PAT_BRUSHED, .param = 0.72},
    [S_STEEL_DARK] = {17, .pattern = PAT_BRUSHED, .param = 0.55},
    [S_BLACK] = {18, RGB(0.07, 0.07, 0.075), GRAIN(0.015)},
    [S_MOUSE_TOP] = {19, COL(0), .pattern = PAT_MOUSE},
    [S_RUBBER] = {20, RGB(0.95, 0.95, 0.93), GRAIN(0.02)},
    [S_SLEEVE] = {21, COL(0), .pattern = PAT_PRINT, .param = 0.003},
    [S_LAPTOP_LID] = {22, RGB(0.70, 0.71, 0.73), .pattern = PAT_LOGO},
    [S_LAPTOP_BASE] = {23, RGB(0.60, 0.61, 0.63), .pattern = PAT_FEET},
    [S_LEATHER] = {24, .base = BASE_MIX, .slot = 0, .rgb = {0.40, 0.22, 0.10}, .mix = 0.5,
                   FINE_GRAIN(0.05), .pattern = PAT_STITCHES},
    [S_TISSUE_BOX] = {25, COL(0), .pattern = PAT_FLOWERS},
    [S_TISSUE_TOP] = {26, COL(0), .pattern = PAT_OPENING},
    [S_CASE] = {27, COL(0), GRAIN(0.03)},
    [S_FABRIC] = {28, COL(0), .pattern = PAT_WEAVE},
    [S_FABRIC_CHECK] = {29, COL(1), .pattern = PAT_WEAVE, .alt = 1},
    [S_BAG] = {30, RGB(0.86, 0.89, 0.92), GRAIN(0.03)},
    [S_BAG_ZIP] = {31, RGB(0.86, 0.89, 0.92), .pattern = PAT_ZIP},
    [S_CUSHION_PAD] = {32, RGB(0.16, 0.16, 0.17), FINE_GRAIN(0.04)},
};

/* ---- temperature fields -------------------------------------------------- */

/* the states a category has no model of its own for */
#define HOT_TOP_COOLER     \
  {                        \
    FIELD_TOP_COOLER, 2, { \
      {45, 60}, { 3, 8 }   \
    }                      \
  }
#define WARM_LOW     \
  {                  \
    FIELD_WARM, 1, { \
      { 8, 14 }      \
    }                \
  }
#define ICED_RISING     \
  {                     \
    FIELD_CHILLED, 2, { \
      {2, 6}, { 8, 12 } \
    }                   \
  }
#define USED_BLOBS      \
  {                     \
    FIELD_USED, 2, {    \
      {3, 7}, { 7, 11 } \
    }                   \
  }
#define FIELD_GENERIC(n) \
  { .stream = n, .hot = HOT_TOP_COOLER, .warm = WARM_LOW, .iced = ICED_RISING, .used = USED_BLOBS }

/* categories without a field of their own share stream 11 */
const synth_field_spec synth_field_other = FIELD_GENERIC(11);

/* ---- the table ----------------------------------------------------------- */

/* draw steps (synth_draw_op): d = dimension, s = the dimension it reads */
#define RANGE(d, lo, hi) \
  { DRAW_RANGE, d, 0, 0, lo, hi }
#define SCALED(d, k, s, lo, hi) \
  { DRAW_SCALED, d, s, k, lo, hi }
#define OFFSET(d, s, lo, hi) \
  { DRAW_OFFSET, d, s, 0, lo, hi }
#define CONST(d, k) \
  { DRAW_CONST, d, 0, k, 0, 0 }
#define TIMES(d, s, k) \
  { DRAW_TIMES, d, s, k, 0, 0 }
#define MINUS(d, s, k) \
  { DRAW_MINUS, d, s, k, 0, 0 }
#define FLAG(d, p) \
  { DRAW_FLAG, d, 0, p, 0, 0 }
#define COLOUR(slot, pal, n) \
  { DRAW_COLOUR, slot, pal, n, 0, 0 }

#define SLOT(part, style)  \
  {                        \
    part, { style, style } \
  }
#define SLOT2(part, style, variant) \
  {                                 \
    part, { style, variant }        \
  }
/* a slab of one part and one style all round */
#define SLAB_ALL(part, style)                                           \
  {                                                                     \
    [SLAB_BOTTOM] = SLOT(part, style), [SLAB_SIDE] = SLOT(part, style), \
    [SLAB_UPPER] = SLOT(part, style), [SLAB_TOP] = SLOT(part, style)    \
  }

/* Each entry: its draws (in their random order), the shape and the part and
 * style of each of the shape's slots (SLOT2: a second style for instances
 * drawn with D_VARIANT), the liquid line, and the field of each state. The
 * entries' order seeds their draws. */
const synth_category synth_categories[SYNTH_N_CATEGORIES] = {
    {.name = "cup",
     .second_state = "hot",
     .draw = {RANGE(D_R, 0.038, 0.043), SCALED(D_R2, 1, D_R, 0.80, 0.92), RANGE(D_H, 0.090, 0.100),
              RANGE(D_T, 0.0035, 0.0045), RANGE(D_T2, 0.006, 0.008), RANGE(D_A, 0.0055, 0.0070),
              RANGE(D_C, 0.0032, 0.0040), RANGE(D_REACH, 0.033, 0.040), RANGE(D_FILL, 0.78, 0.88),
              FLAG(D_VARIANT, 0.5)},
     .shape = SHAPE_VESSEL,
     .slots = {[VESSEL_BODY] = SLOT2("body", S_GLAZE, S_GLAZE_BAND),
               [VESSEL_BOTTOM] = SLOT("bottom", S_UNGLAZED),
               [VESSEL_RIM] = SLOT("rim", S_GLAZE),
               [VESSEL_INNER] = SLOT("inner", S_GLAZE),
               [VESSEL_HANDLE] = SLOT("handle", S_GLAZE)},
     .vessel = {.foot = 0.003, .foot_steps = 2, .inner_round = 0.004, .mug = {0.78, 0.28, 1.33}},
     .fill = FILL_DRAWN,
     .wrapped_fill = 0.8,
     .field = {.stream = 0,
               .hot = {FIELD_CUP,
                       6,
                       {{55, 62}, {35, 40}, {34, 38}, {29.5, 32}, {0.003, 0.005}, {3, 6}}},
               .warm = WARM_LOW,
               .iced = ICED_RISING,
               .used = USED_BLOBS}},

    {.name = "canned_drink",
     .second_state = "iced",
     .draw = {RANGE(D_R, 0.0325, 0.0335), RANGE(D_H, 0.119, 0.123), CONST(D_FILL, 0.92)},
     .shape = SHAPE_CAN,
     .slots = {[CAN_BODY] = SLOT("body", S_CAN_LABEL),
               [CAN_RIM] = SLOT("top", S_ALU),
               [CAN_LID] = SLOT("top", S_ALU_TOP),
               [CAN_DOME] = SLOT("bottom", S_ALU_TOP),
               [CAN_FOOT] = SLOT("bottom", S_ALU)},
     .fill = FILL_DRAWN,
     .field = FIELD_GENERIC(1)},

    {.name = "bottled_drink",
     .second_state = "iced",
     .draw = {RANGE(D_R, 0.030, 0.034), RANGE(D_H, 0.20, 0.23), RANGE(D_R2, 0.0125, 0.0135),
              CONST(D_FILL, 0.85), COLOUR(1, PAL_VIVID, 6)},
     .shape = SHAPE_BOTTLE,
     .slots = {[BOTTLE_BODY] = SLOT("body", S_CLEAR),
               [BOTTLE_LABEL] = SLOT("label", S_BOTTLE_LABEL),
               [BOTTLE_NECK] = SLOT("neck", S_CLEAR),
               [BOTTLE_CAP] = SLOT("cap", S_CAP),
               [BOTTLE_BOTTOM] = SLOT("bottom", S_CLEAR)},
     .fill = FILL_DRAWN,
     .field = FIELD_GENERIC(2)},

    {.name = "orange",
     .second_state = "iced",
     .draw = {RANGE(D_R, 0.036, 0.042), SCALED(D_H, 2, D_R, 0.90, 0.96)},
     .shape = SHAPE_SPHEROID,
     .slots =
         {[SPHEROID_PEEL] = SLOT("peel", S_PEEL), [SPHEROID_STEM] = SLOT("stem_end", S_PEEL_TOP)},
     .fill = FILL_DRAWN,
     .field = {.stream = 3,
               .hot = HOT_TOP_COOLER,
               .warm = WARM_LOW,
               .iced = {FIELD_CHILLED_FRUIT, 2, {{5, 8}, {1, 2.5}}},
               .used = USED_BLOBS}},

    {.name = "smartphone",
     .second_state = "warm",
     .draw = {RANGE(D_W, 0.070, 0.076), RANGE(D_L, 0.145, 0.160), RANGE(D_H, 0.0075, 0.0090),
              RANGE(D_RC, 0.008, 0.011), RANGE(D_E, 0.0022, 0.0030), COLOUR(0, PAL_DARK, 6)},
     .shape = SHAPE_SLAB,
     .slots = {[SLAB_BOTTOM] = SLOT("back", S_PHONE_BACK),
               [SLAB_SIDE] = SLOT("frame", S_FRAME),
               [SLAB_UPPER] = SLOT("frame", S_FRAME),
               [SLAB_TOP] = SLOT("screen", S_SCREEN)},
     .fill = FILL_DRAWN,
     .field = {.stream = 4,
               .hot = {FIELD_PHONE, 4, {{30, 33}, {42, 46}, {43, 47}, {36, 39}}},
               .warm = {FIELD_PHONE, 4, {{27, 29}, {36, 40}, {37, 41}, {31, 33}}},
               .iced = ICED_RISING,
               .used = USED_BLOBS}},

    {.name = "sponge",
     .second_state = "hot",
     .draw = {RANGE(D_W, 0.070, 0.095), RANGE(D_L, 0.100, 0.150), RANGE(D_ZSPLIT, 0.020, 0.030),
              OFFSET(D_H, D_ZSPLIT, 0.005, 0.008), CONST(D_RC, 0.006), CONST(D_E, 0.0025)},
     .shape = SHAPE_SLAB,
     .slots = {[SLAB_BOTTOM] = SLOT("foam", S_FOAM),
               [SLAB_SIDE] = SLOT("foam", S_FOAM),
               [SLAB_UPPER] = SLOT("pad", S_PAD),
               [SLAB_TOP] = SLOT("pad", S_PAD)},
     .fill = FILL_DRAWN,
     .field = {.stream = 5,
               .hot = {FIELD_SPONGE, 3, {{45, 50}, {3, 6}, {1, 2.5}}},
               .warm = WARM_LOW,
               .iced = ICED_RISING,
               .used = USED_BLOBS}},

    {.name = "electric_kettle",
     .second_state = "hot",
     .draw = {RANGE(D_R, 0.070, 0.085), RANGE(D_H, 0.17, 0.21), RANGE(D_T, 0.018, 0.024),
              RANGE(D_REACH, 0.055, 0.065), RANGE(D_FILL, 0.5, 0.7), FLAG(D_VARIANT, 0.6)},
     .shape = SHAPE_KETTLE,
     .slots = {[KETTLE_BASE] = SLOT("base", S_BLACK),
               [KETTLE_BODY] = SLOT2("body", S_PLAIN, S_STEEL),
               [KETTLE_LID] = SLOT2("lid", S_PLAIN, S_STEEL),
               [KETTLE_KNOB] = SLOT("lid", S_BLACK),
               [KETTLE_HANDLE] = SLOT("handle", S_BLACK),
               [KETTLE_SPOUT] = SLOT2("spout", S_PLAIN, S_STEEL)},
     .fill = FILL_ABOVE_BASE,
     .wrapped_fill = 0.6,
     .field = {.stream = 6,
               .hot = {FIELD_KETTLE,
                       7,
                       {{80, 90}, {68, 76}, {60, 70}, {30, 35}, {30, 38}, {60, 72}, {0.005, 0.008}}},
               .warm = WARM_LOW,
               .iced = ICED_RISING,
               .used = USED_BLOBS}},

    {.name = "pot",
     .second_state = "hot",
     .draw = {RANGE(D_R, 0.090, 0.115), RANGE(D_H, 0.095, 0.14), CONST(D_T, 0.003),
              RANGE(D_FILL, 0.5, 0.7), FLAG(D_VARIANT, 0.5), TIMES(D_R2, D_R, 1),
              CONST(D_T2, 0.005), CONST(D_REACH, 0.035), CONST(D_A, 0.009), CONST(D_C, 0.0045)},
     .shape = SHAPE_VESSEL,
     .slots = {[VESSEL_BODY] = SLOT("body", S_STEEL),
               [VESSEL_BOTTOM] = SLOT("bottom", S_STEEL_DARK),
               [VESSEL_RIM] = SLOT("rim", S_STEEL),
               [VESSEL_INNER] = SLOT("inner", S_STEEL_DARK),
               [VESSEL_HANDLE] = SLOT("handle", S_BLACK),
               [VESSEL_LID] = SLOT("lid", S_STEEL),
               [VESSEL_KNOB] = SLOT("lid", S_BLACK)},
     .vessel = {.margin = 0.004,
                .foot = 0.008,
                .foot_steps = 3,
                .inner_round = 0.006,
                .lugs = 1,
                .lug = {0.025, 0.011},
                .lid = 1},
     .fill = FILL_DEPTH,
     .wrapped_fill = 0.6,
     .field = {.stream = 7,
               .hot = {FIELD_POT,
                       6,
                       {{65, 80}, {52, 62}, {40, 48}, {32, 37}, {55, 66}, {0.004, 0.007}}},
               .warm = WARM_LOW,
               .iced = ICED_RISING,
               .used = USED_BLOBS}},

    {.name = "mouse",
     .second_state = "used",
     .draw = {RANGE(D_W, 0.058, 0.066), RANGE(D_L, 0.100, 0.120), RANGE(D_H, 0.033, 0.040),
              TIMES(D_RC, D_W, 0.45), CONST(D_E, 0.003), COLOUR(0, PAL_DARK, 4),
              MINUS(D_BULGE, D_H, 0.012)},
     .shape = SHAPE_SLAB,
     .slots = {[SLAB_BOTTOM] = SLOT("bottom", S_BLACK),
               [SLAB_SIDE] = SLOT("side", S_MOUSE_TOP),
               [SLAB_UPPER] = SLOT("side", S_MOUSE_TOP),
               [SLAB_TOP] = SLOT("shell", S_MOUSE_TOP)},
     .fill = FILL_DRAWN,
     .field = {.stream = 8,
               .hot = HOT_TOP_COOLER,
               .warm = WARM_LOW,
               .iced = ICED_RISING,
               .used = {FIELD_USED_GRIP, 2, {{3, 7}, {7, 11}}}}},

    {.name = "eraser",
     .draw = {RANGE(D_W, 0.020, 0.025), RANGE(D_L, 0.045, 0.065), RANGE(D_H, 0.010, 0.013),
              CONST(D_RC, 0.002), CONST(D_E, 0.0012), TIMES(D_ZSPLIT, D_H, 0.5)},
     .shape = SHAPE_SLAB, /* the sleeve covers the upper half of the side */
     .slots = {[SLAB_BOTTOM] = SLOT("body", S_RUBBER),
               [SLAB_SIDE] = SLOT("body", S_RUBBER),
               [SLAB_UPPER] = SLOT("sleeve", S_SLEEVE),
               [SLAB_TOP] = SLOT("body", S_RUBBER)},
     .fill = FILL_DRAWN,
     .field = FIELD_GENERIC(11)},

    {.name = "laptop",
     .second_state = "warm",
     .draw = {RANGE(D_W, 0.30, 0.34), RANGE(D_L, 0.21, 0.235), RANGE(D_H, 0.015, 0.019),
              TIMES(D_ZSPLIT, D_H, 0.55), CONST(D_RC, 0.010), CONST(D_E, 0.004)},
     .shape = SHAPE_SLAB, /* closed: the base below the seam, the lid above */
     .slots = {[SLAB_BOTTOM] = SLOT("base", S_LAPTOP_BASE),
               [SLAB_SIDE] = SLOT("base", S_LAPTOP_BASE),
               [SLAB_UPPER] = SLOT("lid", S_STEEL),
               [SLAB_TOP] = SLOT("lid", S_LAPTOP_LID)},
     .fill = FILL_DRAWN,
     .field = {.stream = 9,
               .hot = HOT_TOP_COOLER,
               .warm = {FIELD_LAPTOP, 3, {{12, 16}, {3, 5}, {2, 4}}},
               .iced = ICED_RISING,
               .used = USED_BLOBS}},

    {.name = "wallet",
     .draw = {RANGE(D_W, 0.105, 0.120), RANGE(D_L, 0.085, 0.095), RANGE(D_H, 0.012, 0.020),
              CONST(D_RC, 0.008), TIMES(D_E, D_H, 0.35), COLOUR(0, PAL_DARK, 6)},
     .shape = SHAPE_SLAB,
     .slots = SLAB_ALL("leather", S_LEATHER),
     .fill = FILL_DRAWN,
     .field = FIELD_GENERIC(11)},

    {.name = "tissue",
     .draw = {RANGE(D_W, 0.22, 0.24), RANGE(D_L, 0.11, 0.125), RANGE(D_H, 0.075, 0.095),
              CONST(D_RC, 0.004), CONST(D_E, 0.002), COLOUR(0, PAL_PASTEL, 6),
              TIMES(D_ZSPLIT, D_H, 0.85)},
     .shape = SHAPE_SLAB,
     .slots = {[SLAB_BOTTOM] = SLOT("box", S_TISSUE_BOX),
               [SLAB_SIDE] = SLOT("box", S_TISSUE_BOX),
               [SLAB_UPPER] = SLOT("top", S_TISSUE_BOX),
               [SLAB_TOP] = SLOT("top", S_TISSUE_TOP)},
     .fill = FILL_DRAWN,
     .field = FIELD_GENERIC(11)},

    {.name = "glasses_case",
     .draw = {RANGE(D_W, 0.155, 0.170), RANGE(D_L, 0.055, 0.065), RANGE(D_H, 0.035, 0.045),
              TIMES(D_RC, D_L, 0.45), TIMES(D_E, D_H, 0.45), COLOUR(0, PAL_DARK, 6),
              TIMES(D_ZSPLIT, D_H, 0.5)},
     .shape = SHAPE_SLAB,
     .slots = {[SLAB_BOTTOM] = SLOT("shell", S_CASE),
               [SLAB_SIDE] = SLOT("shell", S_CASE),
               [SLAB_UPPER] = SLOT("lid", S_CASE),
               [SLAB_TOP] = SLOT("lid", S_CASE)},
     .fill = FILL_DRAWN,
     .field = FIELD_GENERIC(11)},

    {.name = "pillow",
     .draw = {RANGE(D_W, 0.45, 0.55), RANGE(D_L, 0.30, 0.36), RANGE(D_H, 0.10, 0.14),
              CONST(D_RC, 0.05), CONST(D_E, 0.035), COLOUR(0, PAL_PASTEL, 6),
              TIMES(D_BULGE, D_H, 0.25)},
     .shape = SHAPE_SLAB,
     .slots = SLAB_ALL("fabric", S_FABRIC),
     .fill = FILL_DRAWN,
     .field = FIELD_GENERIC(11)},

    {.name = "cushion",
     .draw = {RANGE(D_W, 0.38, 0.45), TIMES(D_L, D_W, 1), RANGE(D_H, 0.09, 0.13), CONST(D_RC, 0.04),
              CONST(D_E, 0.03), TIMES(D_BULGE, D_H, 0.25)},
     .shape = SHAPE_SLAB,
     .slots = SLAB_ALL("fabric", S_FABRIC_CHECK),
     .fill = FILL_DRAWN,
     .field = FIELD_GENERIC(11)},

    {.name = "storage_bag",
     .draw = {RANGE(D_W, 0.17, 0.27), RANGE(D_L, 0.15, 0.24), RANGE(D_H, 0.012, 0.025),
              CONST(D_RC, 0.012), TIMES(D_E, D_H, 0.45), TIMES(D_ZSPLIT, D_H, 0.5)},
     .shape = SHAPE_SLAB, /* the zip runs round the middle of the side */
     .slots = {[SLAB_BOTTOM] = SLOT("bag", S_BAG),
               [SLAB_SIDE] = SLOT("bag", S_BAG),
               [SLAB_UPPER] = SLOT("zip", S_BAG_ZIP),
               [SLAB_TOP] = SLOT("bag", S_BAG)},
     .fill = FILL_DRAWN,
     .field = FIELD_GENERIC(11)},

    {.name = "headset",
     .second_state = "used",
     .draw = {RANGE(D_R, 0.038, 0.048), RANGE(D_T, 0.028, 0.036), RANGE(D_W, 0.14, 0.17),
              RANGE(D_A, 0.014, 0.019), RANGE(D_C, 0.004, 0.006), COLOUR(0, PAL_DARK, 4)},
     .shape = SHAPE_HEADSET,
     .slots = {[HEADSET_CUP] = SLOT("cup", S_BLACK),
               [HEADSET_CUSHION] = SLOT("cushion", S_CUSHION_PAD),
               [HEADSET_BAND] = SLOT("band", S_BLACK)},
     .fill = FILL_DRAWN,
     .field = {.stream = 10,
               .hot = HOT_TOP_COOLER,
               .warm = WARM_LOW,
               .iced = ICED_RISING,
               .used = {FIELD_USED_CUSHION, 2, {{3, 7}, {7, 11}}}}},
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
