/* thermo_json.c - thermal_model.json: the strict reader and the writer
 * (schema: docs/thermal-model.md). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dataset/dataset_json.h"
#include "hearth/thermo.h"

#define THERMO_FORMAT "hearth-thermal-model"
#define THERMO_VERSION 1
#define MAX_CONDUCTANCES (HEARTH_THERMO_MAX_REGIONS * (HEARTH_THERMO_MAX_REGIONS - 1) / 2)

/* every key of obj must be one of `allowed` (NULL-terminated) */
static hearth_status keys_only(hj_ctx *c, const json_t *obj, const char *const *allowed) {
  const char *key;
  json_t *v;
  json_object_foreach((json_t *)obj, key, v) {
    int ok = 0;
    for (size_t i = 0; allowed[i]; i++)
      if (strcmp(key, allowed[i]) == 0) ok = 1;
    if (!ok) {
      size_t mk = hj_push_key(c, key);
      hearth_status s = hj_fail(c, HEARTH_E_PARSE, "unknown key");
      hj_pop(c, mk);
      return s;
    }
  }
  return HEARTH_OK;
}

static hearth_status get_range(hj_ctx *c, const json_t *obj, const char *key, double lo, double hi,
                               double *out) {
  hearth_status s = hj_get_number(c, obj, key, out);
  if (s != HEARTH_OK) return s;
  if (!(*out >= lo && *out <= hi)) {
    size_t mk = hj_push_key(c, key);
    s = hj_fail(c, HEARTH_E_RANGE, "%g outside [%g, %g]", *out, lo, hi);
    hj_pop(c, mk);
  }
  return s;
}

static const char *const k_top_keys[] = {"format",  "version",      "category", "T_air",
                                         "regions", "conductances", "offsets",  NULL};
static const char *const k_region_keys[] = {"name",   "C",          "T",     "area",
                                            "h_conv", "emissivity", "label", NULL};
static const char *const k_link_keys[] = {"a", "b", "G", NULL};

static hearth_status parse_region(hj_ctx *c, const json_t *o, hearth_thermo_net *net) {
  hearth_thermo_region r = {0};
  hearth_status s;
  if (!json_is_object(o))
    return hj_fail(c, HEARTH_E_PARSE, "expected an object, found %s", hj_type_name(o));
  if ((s = keys_only(c, o, k_region_keys)) != HEARTH_OK) return s;
  if ((s = hj_get_string(c, o, "name", r.name, sizeof r.name)) != HEARTH_OK) return s;
  if ((s = get_range(c, o, "C", 1e-9, 1e12, &r.C)) != HEARTH_OK) return s;
  if ((s = get_range(c, o, "T", -273.0, 1e4, &r.T)) != HEARTH_OK) return s;
  if ((s = get_range(c, o, "area", 0, 1e6, &r.area)) != HEARTH_OK) return s;
  if ((s = get_range(c, o, "h_conv", 0, 1e6, &r.h_conv)) != HEARTH_OK) return s;
  if ((s = get_range(c, o, "emissivity", 0, 1, &r.emissivity)) != HEARTH_OK) return s;
  if ((s = hj_get_int(c, o, "label", -1, HEARTH_THERMO_MAX_CLUSTERS - 1, &r.label)) != HEARTH_OK)
    return s;
  hearth_err e2;
  if (hearth_thermo_add_region(net, &r, NULL, &e2) != HEARTH_OK)
    return hj_fail(c, e2.status, "%s", e2.msg);
  return HEARTH_OK;
}

static hearth_status parse_link(hj_ctx *c, const json_t *o, hearth_thermo_net *net) {
  char a[HEARTH_THERMO_NAME_MAX], b[HEARTH_THERMO_NAME_MAX];
  double g;
  size_t ia, ib;
  hearth_status s;
  if (!json_is_object(o))
    return hj_fail(c, HEARTH_E_PARSE, "expected an object, found %s", hj_type_name(o));
  if ((s = keys_only(c, o, k_link_keys)) != HEARTH_OK) return s;
  if ((s = hj_get_string(c, o, "a", a, sizeof a)) != HEARTH_OK) return s;
  if ((s = hj_get_string(c, o, "b", b, sizeof b)) != HEARTH_OK) return s;
  if ((s = get_range(c, o, "G", 0, 1e9, &g)) != HEARTH_OK) return s;
  hearth_err e2;
  if (hearth_thermo_find(net, a, &ia, &e2) != HEARTH_OK ||
      hearth_thermo_find(net, b, &ib, &e2) != HEARTH_OK)
    return hj_fail(c, HEARTH_E_INCONSISTENT, "%s", e2.msg);
  if (ia == ib) return hj_fail(c, HEARTH_E_INCONSISTENT, "a region linked to itself");
  if (net->G[ia][ib] != 0) return hj_fail(c, HEARTH_E_INCONSISTENT, "link %s-%s given twice", a, b);
  net->G[ia][ib] = net->G[ib][ia] = g;
  return HEARTH_OK;
}

static hearth_status parse_doc(hj_ctx *c, const json_t *root, hearth_thermo_model *m) {
  hearth_status s;
  char fmt[64];
  long long version;
  json_t *arr;
  size_t n;
  if ((s = keys_only(c, root, k_top_keys)) != HEARTH_OK) return s;
  if ((s = hj_get_string(c, root, "format", fmt, sizeof fmt)) != HEARTH_OK) return s;
  if (strcmp(fmt, THERMO_FORMAT) != 0) {
    size_t mk = hj_push_key(c, "format");
    s = hj_fail(c, HEARTH_E_UNSUPPORTED, "expected \"%s\"", THERMO_FORMAT);
    hj_pop(c, mk);
    return s;
  }
  if ((s = hj_get_integer(c, root, "version", THERMO_VERSION, THERMO_VERSION, &version)) !=
      HEARTH_OK)
    return s;
  if ((s = hj_get_string(c, root, "category", m->category, sizeof m->category)) != HEARTH_OK)
    return s;
  if ((s = get_range(c, root, "T_air", -273.0, 1e4, &m->net.T_air)) != HEARTH_OK) return s;
  if ((s = hj_get_string(c, root, "offsets", m->offsets, sizeof m->offsets)) != HEARTH_OK) return s;
  if (m->offsets[0] && !hj_relative_path_ok(m->offsets)) {
    size_t mk = hj_push_key(c, "offsets");
    s = hj_fail(c, HEARTH_E_RANGE, "expected a relative path without '..'");
    hj_pop(c, mk);
    return s;
  }
  if ((s = hj_member(c, root, "regions", &arr)) != HEARTH_OK) return s;
  size_t mk = hj_push_key(c, "regions");
  s = hj_array(c, arr, 1, HEARTH_THERMO_MAX_REGIONS, &n);
  for (size_t i = 0; s == HEARTH_OK && i < n; i++) {
    size_t mi = hj_push_index(c, i);
    s = parse_region(c, json_array_get(arr, i), &m->net);
    hj_pop(c, mi);
  }
  hj_pop(c, mk);
  if (s != HEARTH_OK) return s;
  if ((s = hj_member(c, root, "conductances", &arr)) != HEARTH_OK) return s;
  mk = hj_push_key(c, "conductances");
  s = hj_array(c, arr, 0, MAX_CONDUCTANCES, &n);
  for (size_t i = 0; s == HEARTH_OK && i < n; i++) {
    size_t mi = hj_push_index(c, i);
    s = parse_link(c, json_array_get(arr, i), &m->net);
    hj_pop(c, mi);
  }
  hj_pop(c, mk);
  return s;
}

hearth_status hearth_thermo_model_parse(const char *text, size_t len, const char *name,
                                        hearth_thermo_model *out, hearth_err *err) {
  memset(out, 0, sizeof *out);
  hearth_thermo_net_init(&out->net);
  hj_ctx c;
  hj_init(&c, name, err);
  json_t *root;
  hearth_status s = hj_load(&c, text, len, &root);
  if (s != HEARTH_OK) return s;
  s = parse_doc(&c, root, out);
  json_decref(root);
  if (s != HEARTH_OK) {
    memset(out, 0, sizeof *out);
    hearth_thermo_net_init(&out->net);
  }
  return s;
}

hearth_status hearth_thermo_model_read(const char *path, hearth_thermo_model *out,
                                       hearth_err *err) {
  char *text;
  size_t len;
  hearth_status s = hj_read_text(path, &text, &len, err);
  if (s != HEARTH_OK) return s;
  s = hearth_thermo_model_parse(text, len, path, out, err);
  free(text);
  return s;
}

static hearth_status validate(const char *text, size_t len, const char *name, hearth_err *err) {
  hearth_thermo_model *m = malloc(sizeof *m);
  if (!m) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: validating", name);
  hearth_status s = hearth_thermo_model_parse(text, len, name, m, err);
  free(m);
  return s;
}

hearth_status hearth_thermo_model_write(const char *path, const hearth_thermo_model *m,
                                        hearth_err *err) {
  const hearth_thermo_net *net = &m->net;
  hearth_status s = hearth_thermo_net_check(net, err);
  if (s != HEARTH_OK) {
    hearth_err_prefix(err, "%s", path);
    return s;
  }
  json_t *root = json_object();
  int ok = root != NULL;
  ok = ok && hj_set(root, "format", json_string(THERMO_FORMAT));
  ok = ok && hj_set(root, "version", json_integer(THERMO_VERSION));
  ok = ok && hj_set(root, "category", hj_str(m->category));
  ok = ok && hj_set(root, "T_air", hj_real(net->T_air));
  ok = ok && hj_set(root, "offsets", hj_str(m->offsets));
  json_t *regions = json_array();
  ok = ok && hj_set(root, "regions", regions);
  for (size_t i = 0; ok && i < net->n; i++) {
    const hearth_thermo_region *r = &net->region[i];
    json_t *o = json_object();
    ok = o && json_array_append_new(regions, o) == 0;
    ok = ok && hj_set(o, "name", hj_str(r->name));
    ok = ok && hj_set(o, "C", hj_real(r->C));
    ok = ok && hj_set(o, "T", hj_real(r->T));
    ok = ok && hj_set(o, "area", hj_real(r->area));
    ok = ok && hj_set(o, "h_conv", hj_real(r->h_conv));
    ok = ok && hj_set(o, "emissivity", hj_real(r->emissivity));
    ok = ok && hj_set(o, "label", json_integer(r->label));
  }
  json_t *links = json_array();
  ok = ok && hj_set(root, "conductances", links);
  for (size_t i = 0; ok && i < net->n; i++)
    for (size_t j = i + 1; ok && j < net->n; j++) {
      if (net->G[i][j] == 0) continue;
      json_t *o = json_object();
      ok = o && json_array_append_new(links, o) == 0;
      ok = ok && hj_set(o, "a", hj_str(net->region[i].name));
      ok = ok && hj_set(o, "b", hj_str(net->region[j].name));
      ok = ok && hj_set(o, "G", hj_real(net->G[i][j]));
    }
  if (!ok) {
    json_decref(root);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: building the document", path);
  }
  return hj_write_doc(path, root, validate, err);
}
