/* hearth inspect FILE...: read any file hearth understands with the same
 * strict readers the pipeline uses, and summarise it. */
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/hearth.h"

static const char *k_about =
    "Reads each file with hearth's strict readers and prints a summary, or the exact\n"
    "problem (file, line/column or JSON path) and exits 1. The kind follows from the\n"
    "name, or --as.\n";

static int ends_with(const char *s, const char *suf) {
  size_t a = strlen(s), b = strlen(suf);
  return a >= b && !strcmp(s + a - b, suf);
}

static const char *guess_kind(const char *path) {
  const char *base = strrchr(path, '/');
  base = base ? base + 1 : path;
  if (ends_with(path, ".csv")) return "csv";
  if (ends_with(path, ".png")) return "png";
  if (ends_with(path, ".jpg") || ends_with(path, ".jpeg")) return "jpeg";
  if (ends_with(path, ".npy")) return "npy";
  if (ends_with(path, ".glb")) return "glb";
  if (!strcmp(base, "rig.json")) return "rig";
  if (!strcmp(base, "factory.json")) return "factory";
  if (!strcmp(base, "manifest.json")) return "manifest";
  if (!strncmp(base, "poses", 5) && ends_with(base, ".json")) return "poses";
  if (!strcmp(base, "detections.json")) return "detections";
  if (!strcmp(base, "scale.json")) return "scale";
  if (!strcmp(base, "instance.json")) return "instance";
  if (!strcmp(base, "release.json")) return "release";
  if (base[0] == 'v' && ends_with(base, ".json")) return "depth-intrinsics";
  return NULL;
}

static void print_cam(const char *name, const hearth_camera *c) {
  printf("  %-8s %dx%d fx %.3f fy %.3f cx %.3f cy %.3f dist [%.5f %.5f %.5f %.5f %.5f", name,
         c->width, c->height, c->fx, c->fy, c->cx, c->cy, c->dist[0], c->dist[1], c->dist[2],
         c->dist[3], c->dist[4]);
  if (c->model == HEARTH_LENS_RATIONAL8)
    printf(" %.5f %.5f %.5f] (rational)\n", c->dist[5], c->dist[6], c->dist[7]);
  else printf("]\n");
}

/* a thermal CSV: its statistics, the layout the reader recognised, its metadata */
static hearth_status inspect_csv(const char *path, hearth_err *err) {
  hearth_csv_opts o = {0, 0};
  hearth_image im = {0};
  hearth_thermal_info in;
  hearth_status s = hearth_thermal_read_csv_ex(path, &o, &im, &in, err);
  if (s) return s;
  const float *p = im.data;
  double lo = INFINITY, hi = -INFINITY, sum = 0;
  size_t n = im.width * im.height;
  for (size_t i = 0; i < n; i++) {
    lo = p[i] < lo ? p[i] : lo;
    hi = p[i] > hi ? p[i] : hi;
    sum += p[i];
  }
  printf("%s: thermal CSV %zux%zu, min %.2f, mean %.2f, max %.2f degC\n", path, im.width, im.height,
         lo, n ? sum / (double)n : 0.0, hi);
  char sep[8], dec[8];
  snprintf(sep, sizeof sep, in.separator == '\t' ? "tab" : "'%c'", in.separator);
  snprintf(dec, sizeof dec, in.decimal_mark ? "'%c'" : "none", in.decimal_mark);
  printf("  layout %s", hearth_csv_layout_name(in.layout));
  if (in.label) printf(" (label '%s')", in.label);
  if (in.size_line) printf(" (size line %zu)", in.size_line);
  printf(", separator %s, decimal mark %s, encoding %s, line ends %s\n", sep, dec, in.encoding,
         in.line_ends);
  printf("  matrix lines %zu..%zu after %zu header line(s), unit %s\n", in.first_line, in.last_line,
         in.header_lines, in.unit ? "degC (stated)" : "degC (not stated)");
  for (size_t i = 0; i < in.n_meta; i++)
    printf("  metadata line %zu: %s%s%s\n", in.meta[i].line, in.meta[i].key,
           in.meta[i].value[0] ? " = " : "", in.meta[i].value);
  if (in.n_meta_lines > in.n_meta)
    printf("  (%zu more metadata lines)\n", in.n_meta_lines - in.n_meta);
  hearth_thermal_info_free(&in);
  hearth_image_free(&im);
  return HEARTH_OK;
}

static hearth_status inspect_one(const char *path, const char *kind, hearth_err *err) {
  hearth_status s = HEARTH_OK;
  if (!strcmp(kind, "csv")) {
    return inspect_csv(path, err);
  } else if (!strcmp(kind, "png") || !strcmp(kind, "jpeg")) {
    hearth_image im = {0};
    s = !strcmp(kind, "png") ? hearth_png_read(path, &im, err) : hearth_jpeg_read(path, &im, err);
    if (s) return s;
    printf("%s: %s %zux%zu, %d channel(s), %d-bit\n", path, kind, im.width, im.height, im.channels,
           8 * (int)im.type);
    hearth_image_free(&im);
  } else if (!strcmp(kind, "npy")) {
    hearth_npy a = {0};
    if ((s = hearth_npy_read(path, &a, err))) return s;
    printf("%s: npy %s shape (", path, a.dtype == HEARTH_NPY_F32 ? "float32" : "uint8");
    for (int i = 0; i < a.ndim; i++) printf("%s%zu", i ? ", " : "", a.shape[i]);
    size_t n = hearth_npy_count(&a), finite = 0;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
      double v = a.dtype == HEARTH_NPY_F32 ? ((float *)a.data)[i] : ((uint8_t *)a.data)[i];
      if (!isfinite(v)) continue;
      finite++;
      lo = v < lo ? v : lo;
      hi = v > hi ? v : hi;
    }
    printf("), %zu finite of %zu, range [%g, %g]\n", finite, n, finite ? lo : 0.0,
           finite ? hi : 0.0);
    hearth_npy_free(&a);
  } else if (!strcmp(kind, "glb")) {
    hearth_glb_read_opts o = {.load_texture = 1};
    hearth_mesh m = {0};
    if ((s = hearth_glb_read(path, &o, &m, err))) return s;
    double lo[3], hi[3];
    hearth_mesh_bounds(&m, lo, hi);
    uint32_t n_isl = 0;
    if (m.uvs) {
      uint32_t *isl = hearth_alloc_array(m.n_triangles ? m.n_triangles : 1, sizeof *isl);
      if (isl && hearth_uv_islands(&m, isl, &n_isl, NULL)) n_isl = 0;
      free(isl);
    }
    printf(
        "%s: GLB %zu vertices, %zu triangles, UVs %s (%u islands), texture %s%zux%zu\n"
        "  bounds [%.4f %.4f %.4f] .. [%.4f %.4f %.4f] (size %.4f x %.4f x %.4f)\n",
        path, m.n_vertices, m.n_triangles, m.uvs ? "yes" : "no", n_isl,
        m.texture.data ? "" : "none ", m.texture.width, m.texture.height, lo[0], lo[1], lo[2],
        hi[0], hi[1], hi[2], hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    hearth_mesh_free(&m);
  } else if (!strcmp(kind, "rig")) {
    hearth_rig r;
    if ((s = hearth_rig_read(path, &r, err))) return s;
    if (r.thermal_only) {
      printf("%s: thermal-only rig (no colour camera, no T_thermal_from_rgb)\n", path);
      print_cam("thermal", &r.thermal);
      printf("  thermal rms %.3f px\n", r.thermal_rms_px);
      return HEARTH_OK;
    }
    printf("%s: rig\n", path);
    print_cam("rgb", &r.rgb);
    print_cam("thermal", &r.thermal);
    print_cam("depth", &r.depth);
    printf("  T_thermal_from_rgb t [%.5f %.5f %.5f] m, thermal rms %.3f px, stereo rms %.3f px\n",
           r.T_thermal_from_rgb.t[0], r.T_thermal_from_rgb.t[1], r.T_thermal_from_rgb.t[2],
           r.thermal_rms_px, r.stereo_rms_px);
  } else if (!strcmp(kind, "factory")) {
    hearth_factory_calib f;
    if ((s = hearth_factory_read(path, &f, err))) return s;
    printf("%s: factory calibration\n", path);
    print_cam("rgb", &f.rgb);
    print_cam("depth", &f.depth);
    printf("  T_depth_from_rgb t [%.5f %.5f %.5f] m\n", f.T_depth_from_rgb.t[0],
           f.T_depth_from_rgb.t[1], f.T_depth_from_rgb.t[2]);
  } else if (!strcmp(kind, "manifest")) {
    hearth_manifest m = {0};
    if ((s = hearth_manifest_read(path, &m, err))) return s;
    printf("%s: manifest of %s/%s, %zu views\n", path, m.instance, m.state, m.n_views);
    hearth_manifest_free(&m);
  } else if (!strcmp(kind, "poses")) {
    hearth_poses p = {0};
    if ((s = hearth_poses_read(path, &p, err))) return s;
    printf("%s: %zu poses\n", path, p.n);
    hearth_poses_free(&p);
  } else if (!strcmp(kind, "detections")) {
    hearth_detections d = {0};
    if ((s = hearth_detections_read(path, &d, err))) return s;
    size_t found = 0;
    for (size_t i = 0; i < d.n; i++) found += d.frames[i].found != 0;
    printf("%s: %zu frames, plate found in %zu\n", path, d.n, found);
    hearth_detections_free(&d);
  } else if (!strcmp(kind, "scale")) {
    hearth_scale_doc sc;
    if ((s = hearth_scale_doc_read(path, &sc, err))) return s;
    printf("%s: scale %.6f from %d views, residual median %.3f mm\n", path, sc.scale, sc.views_used,
           sc.residual_median_mm);
  } else if (!strcmp(kind, "instance")) {
    hearth_instance_doc d;
    if ((s = hearth_instance_read(path, &d, err))) return s;
    printf("%s: instance %s (%s), %zu state(s):", path, d.id, d.category, d.n_states);
    for (size_t i = 0; i < d.n_states; i++) printf(" %s", d.states[i]);
    printf("\n");
  } else if (!strcmp(kind, "release")) {
    hearth_release_doc d = {0};
    if ((s = hearth_release_read(path, &d, err))) return s;
    printf("%s: release '%s' %s, %zu instance(s)\n", path, d.name, d.version, d.n_instances);
    hearth_release_free(&d);
  } else if (!strcmp(kind, "depth-intrinsics")) {
    hearth_depth_intrinsics d;
    if ((s = hearth_depth_intrinsics_read(path, &d, err))) return s;
    printf("%s: depth intrinsics\n", path);
    print_cam("depth", &d.depth);
  } else {
    return hearth_err_set(err, HEARTH_E_ARG, "%s: unknown kind '%s'", path, kind);
  }
  return HEARTH_OK;
}

/* the kinds of --as */
static const char *const k_kinds[] =
    {"csv",      "png",   "jpeg",       "npy",   "glb",      "rig",     "factory",
     "manifest", "poses", "detections", "scale", "instance", "release", "depth-intrinsics",
     NULL};

int hearth_cmd_inspect(int argc, char **argv) {
  int as = -1;
  const cli_opt opts[] = {
      CLI_CHOICE("--as", &as, k_kinds, NULL, "read every file as KIND", .metavar = "KIND",
                 .def = "from the name"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth inspect",
                           .args = "FILE",
                           .min_args = 1,
                           .max_args = -1,
                           .about = k_about,
                           .opts = opts};
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) return rc;
  rc = 0;
  for (int i = 0; i < args.n; i++) {
    const char *kind = as >= 0 ? k_kinds[as] : guess_kind(args.v[i]);
    hearth_err err = {0};
    if (!kind) {
      fprintf(stderr, "hearth inspect: %s: cannot tell the kind from the name; use --as\n",
              args.v[i]);
      rc = 1;
      continue;
    }
    if (inspect_one(args.v[i], kind, &err)) rc = cli_fail("inspect", &err);
  }
  return rc;
}
