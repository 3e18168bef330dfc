/* hearth synth: write a release with the virtual capture rig. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/dataset.h"
#include "hearth/synth.h"

static void synth_usage(FILE *out) {
  fprintf(out,
          "usage: hearth synth --out DIR [options]\n\n"
          "Make a release tree with the virtual capture rig (a digital twin of the\n"
          "paper's RGB-thermal-depth rig), including ground_truth/. DIR must not exist\n"
          "or be empty; the tree is built beside it and renamed into place.\n\n"
          "options:\n"
          "  --out DIR            release root to create (required)\n"
          "  --seed N             random seed (default 1); same seed, same bytes\n"
          "  --categories a,b     object categories (default cup; 'all' = every\n"
          "                       procedural category)\n"
          "  --instances N        instances per category (default 1)\n"
          "  --states s1,s2       states per instance (default: the category's own,\n"
          "                       e.g. cup: neutral,hot)\n"
          "  --views N            views per state, 1..30 (default 30 = 3 x 10)\n"
          "  --triangles N        mesh detail (default 20000)\n"
          "  --texture N          RGB texture side (default 1024)\n"
          "  --map-res R          side of the ground-truth temperature maps (default 1024)\n"
          "  --no-calibration     skip the calibration plate captures\n"
          "  --thermal-frames N   thermal-only plate frames (default 27)\n"
          "  --stereo-pairs N     RGB-thermal plate pairs (default 24)\n"
          "  --mesh FILE.glb      put this UV-mapped mesh on the turntable instead\n"
          "  --mesh-size M        its largest extent in metres (default 0.12)\n"
          "  --mesh-category C    whose temperature states it gets (default cup)\n"
          "  --contact-sheet      also write raw/<state>/contact_sheet.png\n"
          "  --draft-rgb          render object colour views at a quarter size, enlarged 4x to\n"
          "                       1920x1080 (16x faster colour; for tests and quick looks)\n"
          "  --netd C             thermal noise in degC (default 0.05)\n"
          "  --threads N          worker threads (default: HEARTH_THREADS or all cores)\n"
          "  --quiet              no progress output\n"
          "  -h, --help           this text\n\n"
          "categories:");
  const char *names[64];
  size_t n = hearth_synth_categories(names, 64);
  for (size_t i = 0; i < n && i < 64; i++) fprintf(out, " %s", names[i]);
  fprintf(out, "\n");
}

/* split a comma list into dst (pointers into a copy owned by *store) */
static int split_list(const char *s, char **store, const char **dst, size_t max, size_t *n) {
  free(*store);
  *store = strdup(s);
  if (!*store) return 0;
  *n = 0;
  for (char *tok = strtok(*store, ","); tok; tok = strtok(NULL, ",")) {
    if (!*tok) continue;
    if (*n >= max) return 0;
    dst[(*n)++] = tok;
  }
  return *n > 0;
}

static int bad(const char *opt, const char *val, const char *want) {
  fprintf(stderr, "hearth synth: option %s: invalid value '%s' (expected %s)\n", opt,
          val ? val : "", want);
  return 2;
}

int hearth_cmd_synth(int argc, char **argv) {
  hearth_synth_opts o;
  hearth_synth_opts_default(&o);
  char *cat_store = NULL, *state_store = NULL;
  int rc = 0;
  for (int i = 1; i < argc && !rc; i++) {
    const char *v = NULL;
    long n;
    double x;
    int r;
    if (cli_is_help(argv[i])) {
      synth_usage(stdout);
      free(cat_store);
      free(state_store);
      return 0;
    }
#define OPT(name) ((r = cli_opt(argc, argv, &i, name, &v)) != 0)
#define NEEDVAL(name)                                                              \
  if (r < 0) {                                                                     \
    fprintf(stderr, "hearth synth: option %s needs a value\n", name);              \
    rc = 2;                                                                        \
    break;                                                                         \
  }
    if (OPT("--out")) {
      NEEDVAL("--out");
      o.out_root = v;
    } else if (OPT("--seed")) {
      NEEDVAL("--seed");
      if (!cli_parse_u64(v, &o.seed)) rc = bad("--seed", v, "a non-negative integer");
    } else if (OPT("--categories")) {
      NEEDVAL("--categories");
      if (!strcmp(v, "all")) {
        o.n_categories = 0;
      } else if (!split_list(v, &cat_store, o.categories, HEARTH_SYNTH_MAX_ITEMS,
                             &o.n_categories)) {
        rc = bad("--categories", v, "a comma-separated list of categories");
      }
    } else if (OPT("--instances")) {
      NEEDVAL("--instances");
      if (cli_parse_int(v, 1, 99, &n)) o.instances_per_category = (int)n;
      else rc = bad("--instances", v, "an integer 1..99");
    } else if (OPT("--states")) {
      NEEDVAL("--states");
      if (!split_list(v, &state_store, o.states, 8, &o.n_states))
        rc = bad("--states", v, "a comma-separated list of states");
    } else if (OPT("--views")) {
      NEEDVAL("--views");
      if (cli_parse_int(v, 1, 30, &n)) o.n_views = (int)n;
      else rc = bad("--views", v, "an integer 1..30");
    } else if (OPT("--triangles")) {
      NEEDVAL("--triangles");
      if (cli_parse_int(v, 100, 5000000, &n)) o.triangles = (size_t)n;
      else rc = bad("--triangles", v, "an integer 100..5000000");
    } else if (OPT("--texture")) {
      NEEDVAL("--texture");
      if (cli_parse_int(v, 16, 8192, &n)) o.texture_size = (size_t)n;
      else rc = bad("--texture", v, "an integer 16..8192");
    } else if (OPT("--map-res")) {
      NEEDVAL("--map-res");
      if (cli_parse_int(v, 8, 8192, &n)) o.map_resolution = (size_t)n;
      else rc = bad("--map-res", v, "an integer 8..8192");
    } else if (!strcmp(argv[i], "--no-calibration")) {
      o.calibration = 0;
    } else if (OPT("--thermal-frames")) {
      NEEDVAL("--thermal-frames");
      if (cli_parse_int(v, 0, 999, &n)) o.n_thermal_frames = (int)n;
      else rc = bad("--thermal-frames", v, "an integer 0..999");
    } else if (OPT("--stereo-pairs")) {
      NEEDVAL("--stereo-pairs");
      if (cli_parse_int(v, 0, 999, &n)) o.n_stereo_pairs = (int)n;
      else rc = bad("--stereo-pairs", v, "an integer 0..999");
    } else if (OPT("--mesh-size")) {
      NEEDVAL("--mesh-size");
      if (cli_parse_num(v, &x) && x > 0.005 && x < 2.0) o.mesh_size_m = x;
      else rc = bad("--mesh-size", v, "metres, 0.005..2");
    } else if (OPT("--mesh-category")) {
      NEEDVAL("--mesh-category");
      o.mesh_category = v;
    } else if (OPT("--mesh")) {
      NEEDVAL("--mesh");
      o.mesh_path = v;
    } else if (!strcmp(argv[i], "--draft-rgb")) {
      o.rgb_full_size = 0;
    } else if (!strcmp(argv[i], "--contact-sheet")) {
      o.contact_sheet = 1;
    } else if (OPT("--netd")) {
      NEEDVAL("--netd");
      if (cli_parse_num(v, &x) && x >= 0 && x <= 5) o.netd_c = x;
      else rc = bad("--netd", v, "degC, 0..5");
    } else if (OPT("--threads")) {
      NEEDVAL("--threads");
      if (cli_parse_int(v, 1, 1024, &n)) o.threads = (int)n;
      else rc = bad("--threads", v, "an integer 1..1024");
    } else if (!strcmp(argv[i], "--quiet")) {
      o.quiet = 1;
    } else {
      fprintf(stderr, "hearth synth: unknown option '%s' (see 'hearth synth --help')\n", argv[i]);
      rc = 2;
    }
#undef OPT
#undef NEEDVAL
  }
  for (size_t i = 0; !rc && i < o.n_categories; i++)
    if (!hearth_category_valid(o.categories[i]))
      rc = bad("--categories", o.categories[i], "one of the paper's 18 categories, e.g. cup");
  for (size_t i = 0; !rc && i < o.n_states; i++)
    if (!hearth_state_valid(o.states[i]))
      rc = bad("--states", o.states[i], "neutral, hot, warm, iced or used");
  if (!rc && o.mesh_path && !hearth_category_valid(o.mesh_category))
    rc = bad("--mesh-category", o.mesh_category, "one of the paper's 18 categories");
  if (!rc && !o.out_root) {
    fprintf(stderr, "hearth synth: option --out is required (see 'hearth synth --help')\n");
    rc = 2;
  }
  if (!rc) {
    hearth_err err = {0};
    double t0 = hearth_now();
    if (hearth_synth_release(&o, &err) != HEARTH_OK) {
      rc = cli_fail("synth", &err);
    } else if (!o.quiet) {
      fprintf(stderr, "hearth synth: wrote %s in %.1f s\n", o.out_root, hearth_now() - t0);
    }
  }
  free(cat_store);
  free(state_store);
  return rc;
}
