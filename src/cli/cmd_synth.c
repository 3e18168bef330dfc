/* hearth synth: write a release with the virtual capture rig. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/dataset.h"
#include "hearth/synth.h"

static const char *k_about =
    "Make a release tree with the virtual capture rig (a digital twin of the\n"
    "paper's RGB-thermal-depth rig), including ground_truth/. DIR must not exist\n"
    "or be empty; the tree is built beside it and renamed into place.\n";

/* the categories the virtual rig can make, after the options */
static void list_categories(FILE *out) {
  const char *names[64];
  size_t n = hearth_synth_categories(names, 64);
  fprintf(out, "\ncategories:");
  for (size_t i = 0; i < n && i < 64; i++) fprintf(out, " %s", names[i]);
  fprintf(out, "\n");
}

/* --target LATTICE[:RxC] into a target (pitch and hole from the lattice's
 * defaults until --target-pitch / --target-hole) */
static int parse_target(void *dst, const char *value, char *why, size_t whysz) {
  hearth_target *t = dst;
  char name[32];
  const char *colon = strchr(value, ':');
  size_t nl = colon ? (size_t)(colon - value) : strlen(value);
  if (nl >= sizeof name) nl = sizeof name - 1;
  memcpy(name, value, nl);
  name[nl] = 0;
  hearth_lattice l;
  if (!hearth_lattice_parse(name, &l)) {
    snprintf(why, whysz, "unknown lattice '%s'", name);
    return 1;
  }
  /* defaults: the paper's plate; a 6 x 8 hex target; a 7 x 7 grid */
  static const int def_rc[3][2] = {{8, 11}, {6, 8}, {7, 7}};
  static const double def_pitch[3] = {0.012, 0.012, 0.015};
  t->lattice = l;
  t->rows = def_rc[l][0];
  t->cols = def_rc[l][1];
  t->pitch_m = def_pitch[l];
  t->hole_diameter_m = 0.008;
  if (colon) {
    int r, c, used = 0;
    if (sscanf(colon + 1, "%dx%d%n", &r, &c, &used) != 2 || colon[1 + used] != 0) {
      snprintf(why, whysz, "expected LATTICE:RxC, e.g. grid:7x7");
      return 1;
    }
    t->rows = r;
    t->cols = c;
  }
  return 0;
}

static int parse_size(void *dst, const char *value, char *why, size_t whysz) {
  size_t *wh = dst;
  unsigned w, h;
  int used = 0;
  if (sscanf(value, "%ux%u%n", &w, &h, &used) != 2 || value[used] != 0) {
    snprintf(why, whysz, "expected WxH, e.g. 160x120");
    return 1;
  }
  wh[0] = w;
  wh[1] = h;
  return 0;
}

static int category_or_all(const char *s) { return !strcmp(s, "all") || hearth_category_valid(s); }
static int state_ok(const char *s) { return hearth_state_valid(s); }

int hearth_cmd_synth(int argc, char **argv) {
  hearth_synth_opts o;
  hearth_synth_opts_default(&o);
  cli_list cats = {0}, states = {0};
  int thermal_only = 0, wide_angle = 0;
  const char *formats = NULL;
  double pitch = 0, hole = 0;
  size_t tsize[2] = {0, 0};
  static const char *const k_recon[] = {"stand-in", "none", NULL};
  const cli_opt opts[] = {
      CLI_STR("--out", "DIR", &o.out_root, "release root to create", .flags = CLI_REQUIRED),
      CLI_U64("--seed", "N", &o.seed, "random seed; same seed, same bytes"),
      CLI_LIST("--categories", "a,b", &cats, HEARTH_SYNTH_MAX_ITEMS, category_or_all,
               "one of the paper's 18 categories, e.g. cup",
               "object categories ('all' = every procedural category)", .def = "cup"),
      CLI_INT("--instances", "N", &o.instances_per_category, 1, 99, "instances per category"),
      CLI_LIST("--states", "s1,s2", &states, 8, state_ok, "neutral, hot, warm, iced or used",
               "states per instance", .def = "the category's own, e.g. cup: neutral,hot"),
      CLI_INT("--views", "N", &o.n_views, 1, 30,
              "views per state, 1..30; 30 = 3 elevations x 10 azimuths"),
      CLI_SIZE("--triangles", "N", &o.triangles, 100, 5000000, "mesh detail"),
      CLI_SIZE("--texture", "N", &o.texture_size, 16, 8192, "RGB texture side"),
      CLI_SIZE("--map-res", "R", &o.map_resolution, 8, 8192,
               "side of the ground-truth temperature maps"),
      CLI_FLAG("--no-calibration", &o.calibration, 0, "skip the calibration plate captures"),
      CLI_INT("--thermal-frames", "N", &o.n_thermal_frames, 0, 999, "thermal-only plate frames"),
      CLI_INT("--stereo-pairs", "N", &o.n_stereo_pairs, 0, 999, "RGB-thermal plate pairs"),
      CLI_STR("--mesh", "FILE.glb", &o.mesh_path,
              "put this UV-mapped mesh on the turntable instead"),
      CLI_NUM("--mesh-size", "M", &o.mesh_size_m, 0.005, 2.0, "its largest extent in metres",
              .flags = CLI_LO_OPEN | CLI_HI_OPEN),
      CLI_STR("--mesh-category", "C", &o.mesh_category, "whose temperature states it gets"),
      CLI_FLAG("--contact-sheet", &o.contact_sheet, 1, "also write raw/<state>/contact_sheet.png"),
      CLI_NUM("--backdrop-tilt", "DEG", &o.backdrop_tilt_deg, -30, 30,
              "the backdrop behind the turntable leans back by DEG, its top away from the "
              "camera (0: vertical)"),
      CLI_CHOICE("--recon", &o.no_recon, k_recon, NULL,
                 "stand-in: recon/ as an outside tool would hand it over (the true mesh "
                 "under a similarity); none: no recon/ (for `hearth recon`)",
                 .def = "stand-in"),
      CLI_FLAG("--draft-rgb", &o.rgb_full_size, 0,
               "render object colour views at a quarter size, enlarged 4x to 1920x1080 (16x "
               "faster colour; for tests and quick looks)"),
      CLI_NUM("--netd", "C", &o.netd_c, 0, 5, "thermal noise in degC"),
      CLI_CALL("--target", "LATTICE[:RxC]", &o.target, parse_target,
               "hex-alternating, hex or grid, optionally with rows x cols",
               "calibration target, written to calibration/target.json: hex-alternating (the "
               "paper's plate, 8x11), hex (C holes every row, odd rows shifted; 6x8) or grid "
               "(RxC; 7x7)",
               .def = "the paper's plate, no target.json"),
      CLI_NUM("--target-pitch", "M", &pitch, 0.001, 1.0, "hole spacing of --target in metres",
              .def = "hex 0.012, grid 0.015"),
      CLI_NUM("--target-hole", "M", &hole, 0.0005, 0.8, "hole diameter of --target in metres",
              .def = "0.008"),
      CLI_CALL("--thermal-size", "WxH", tsize, parse_size, "WxH pixels, e.g. 160x120",
               "thermal sensor size (64..1280 x 48..1024), e.g. 160x120, 382x288, 640x512",
               .def = "256x192"),
      CLI_FLAG("--thermal-wide", &o.thermal_wide, 1,
               "a ~90 degree thermal lens with strong barrel distortion"),
      CLI_FLAG("--calib-clutter", &o.calib_clutter, 1,
               "calibration frames with a room behind the plate: a window grid, a desk edge, a "
               "warm person, hole-sized spots"),
      CLI_FLAG("--calib-low-contrast", &o.calib_low_contrast, 1,
               "calibration holes only 2-4 degC (colour ~0.2) off the plate"),
      CLI_FLAG("--calib-invert", &o.calib_invert, 1,
               "calibration holes cooler than the plate in thermal, brighter in colour"),
      CLI_FLAG("--ideal", &o.ideal, 1,
               "the clean rig: every effect off (black bodies, nothing cools), for "
               "closed-form tests"),
      CLI_NUM("--emissivity", "S", &o.effects.emissivity, 0, 5,
              "scale of each material's 1 - emissivity (0: black bodies)"),
      CLI_NUM("--grazing", "S", &o.effects.grazing, 0, 1,
              "Fresnel fall-off of emissivity towards grazing, blended in (0: none)"),
      CLI_NUM("--warm-source", "DC", &o.effects.warm_source_c, 0, 100,
              "the operator's excess over ambient mirrored by glossy surfaces (0: none)"),
      CLI_NUM("--cooling", "S", &o.effects.cooling, 0, 100,
              "scale of the Newton cooling rates during the scan (0: none)"),
      CLI_NUM("--scan-time", "S", &o.effects.scan_s, 1, 36000,
              "seconds a state's scan takes (three passes)"),
      CLI_FLAG("--restore-state", &o.effects.restore, 1,
               "restore the state before each pass (its time restarts)"),
      CLI_NUM("--camera-emissivity", "E", &o.effects.camera_emissivity, 0.1, 1,
              "the thermal camera's emissivity setting"),
      CLI_NUM("--plate-thickness", "M", &o.effects.plate_thickness_m, 0, 0.05,
              "calibration plate thickness in metres (0: infinitely thin)",
              .def = "drawn per seed in 0.003..0.006"),
      CLI_NUM("--lamp", "S", &o.effects.lamp, 0, 5,
              "scale of the lamp's hot spot and gradient on the backing (0: even)"),
      CLI_NUM("--plate-warming", "DC", &o.effects.plate_warming_c, 0, 20,
              "the plate's warming over the calibration capture (degC)"),
      CLI_NUM("--vignetting", "S", &o.effects.vignetting, 0, 1,
              "blend of a cos^4 fall-off of thermal contrast (0: none)"),
      CLI_NUM("--fpn-offset", "DC", &o.effects.fpn_offset_c, 0, 5,
              "thermal fixed-pattern offset per pixel, 1 sigma (degC)"),
      CLI_NUM("--fpn-gain", "G", &o.effects.fpn_gain, 0, 0.5,
              "thermal fixed-pattern gain per pixel, 1 sigma"),
      CLI_NUM("--motion-blur", "PX", &o.effects.motion_blur_px, 0, 50,
              "longest linear motion blur of a colour calibration frame (px)"),
      CLI_INT("--calib-jpeg-quality", "Q", &o.effects.jpeg_quality, 1, 100,
              "JPEG quality of the colour calibration frames (--ideal: 92)"),
      CLI_NUM("--trigger-offset", "MS", &o.effects.trigger_ms, 0, 100,
              "longest trigger offset between the two cameras (ms)"),
      CLI_NUM("--hand-speed", "MPS", &o.effects.hand_speed_m_s, 0, 2,
              "speed of the hand-held plate (m/s)"),
      CLI_NUM("--hand-turn", "RPS", &o.effects.hand_turn_rad_s, 0, 10,
              "turn rate of the hand-held plate (rad/s)"),
      CLI_NUM("--rolling-shutter", "MS", &o.effects.rs_readout_ms, 0, 100,
              "the colour camera's rolling-shutter readout of a frame (ms; 0: global shutter)"),
      CLI_NUM("--plate-bow", "M", &o.effects.plate_bow_m, 0, 0.01,
              "largest bow of the calibration plate, centre against corners (m; 0: flat)"),
      CLI_NUM("--plate-flex", "M", &o.effects.plate_flex_m, 0, 0.01,
              "the hand-held plate's flex: each frame's bow changes by up to M (m; 0: rigid)"),
      CLI_NUM("--plate-twist", "M", &o.effects.plate_twist_m, 0, 0.01,
              "the hand-held plate's twist: each frame's corners rise and fall by up to M (m; "
              "0: none)"),
      CLI_NUM("--hole-burr", "M", &o.effects.hole_burr_m, 0, 0.001,
              "1 sigma irregularity of each hole's rim (m; 0: round)"),
      CLI_NUM("--hole-position", "M", &o.effects.hole_position_m, 0, 0.001,
              "1 sigma per axis of each hole's drilled position off the nominal lattice (m; 0: "
              "exact)"),
      CLI_NUM("--calib-roll", "DEG", &o.effects.plate_roll_deg, 0, 180,
              "the plate's turn in its own plane in the calibration frames, drawn in -DEG..DEG "
              "(the paper's plate only; others: 12)"),
      CLI_NUM("--lens-residual", "PX", &o.effects.lens_residual_px, 0, 5,
              "rms per axis of the thermal lens's departure from its 5-parameter model in the "
              "calibration captures (px; 0: the model lens)"),
      CLI_NUM("--rgb-lens-residual", "PX", &o.effects.rgb_residual_px, 0, 5,
              "the same for the colour camera against its factory model (px; 0: the model "
              "lens)"),
      CLI_NUM("--backing-texture", "S", &o.effects.backing_texture, 0, 1,
              "rms of the calibration backing's mm-scale non-uniformity, a fraction of the "
              "hole contrast (0: even)"),
      CLI_INT("--threads", "N", &o.threads, 1, 1024, "worker threads",
              .def = "HEARTH_THREADS or all cores"),
      CLI_FLAG("--quiet", &o.quiet, 1, "no progress output"),
      CLI_FLAG("--thermal-only", &thermal_only, 1,
               "only a thermal-only calibration root: --thermal-frames plate frames of the "
               "thermal camera alone (calibration/captures/thermal/IR_NNNN.*), no instances"),
      CLI_FLAG("--wide-angle", &wide_angle, 1,
               "with --thermal-only: a ~100 degree lens with strong barrel distortion (OpenCV's "
               "rational model) instead of the rig's"),
      CLI_STR("--frame-formats", "LIST", &formats,
              "with --thermal-only: frame formats used in turn, of csv, png8, png8-dark, png16, "
              "png-rgb, tiff8, tiff16, tiff-lzw, tiff-deflate, tiff-packbits",
              .def = "csv,png8,png16,tiff8,tiff16"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth synth",
                           .about = k_about,
                           .opts = opts,
                           .more = list_categories};
  int rc = cli_parse(&cmd, argc, argv, NULL);
  if (rc != CLI_RUN) return rc;
  if (cats.n == 1 && !strcmp(cats.items[0], "all")) {
    o.n_categories = 0;
  } else if (cats.n) {
    for (size_t i = 0; i < cats.n; i++)
      if (!strcmp(cats.items[i], "all"))
        return cli_usage_error(&cmd, "option --categories: 'all' cannot be listed with others");
    o.n_categories = cats.n;
    for (size_t i = 0; i < cats.n; i++) o.categories[i] = cats.items[i];
  }
  if (states.n) {
    o.n_states = states.n;
    for (size_t i = 0; i < states.n; i++) o.states[i] = states.items[i];
  }
  if ((pitch || hole) && !o.target.rows)
    return cli_usage_error(&cmd, "options --target-pitch and --target-hole need --target");
  if (pitch) o.target.pitch_m = pitch;
  if (hole) o.target.hole_diameter_m = hole;
  o.thermal_width = tsize[0];
  o.thermal_height = tsize[1];
  if (o.mesh_path && !hearth_category_valid(o.mesh_category))
    return cli_usage_error(&cmd,
                           "option --mesh-category: expected one of the paper's 18 "
                           "categories, found '%s'",
                           o.mesh_category);
  hearth_err err = {0};
  double t0 = hearth_now();
  if ((wide_angle || formats) && !thermal_only)
    return cli_usage_error(&cmd, "options --wide-angle and --frame-formats need --thermal-only");
  if (thermal_only) {
    hearth_synth_thermal_opts t;
    hearth_synth_thermal_opts_default(&t);
    t.seed = o.seed;
    t.out_root = o.out_root;
    t.n_frames = o.n_thermal_frames;
    t.wide_angle = wide_angle;
    if (formats) t.formats = formats;
    t.netd_c = o.netd_c;
    t.threads = o.threads;
    if (hearth_synth_thermal_only(&t, &err) != HEARTH_OK) return cli_fail("synth", &err);
    if (!o.quiet)
      fprintf(stderr, "hearth synth: wrote %s (thermal-only) in %.1f s\n", o.out_root,
              hearth_now() - t0);
    return 0;
  }
  if (hearth_synth_release(&o, &err) != HEARTH_OK) return cli_fail("synth", &err);
  if (!o.quiet)
    fprintf(stderr, "hearth synth: wrote %s in %.1f s\n", o.out_root, hearth_now() - t0);
  return 0;
}
