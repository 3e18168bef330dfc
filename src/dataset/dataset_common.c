/* Plumbing shared by the documents (dataset_docs.c, dataset_views.c):
 * parse or read a document through its from-JSON function, checked
 * strings, and duplicate keys among a document's records. */
#include <stdlib.h>
#include <string.h>

#include "dataset/dataset_internal.h"

hearth_status hr_parse_doc(const char *text, size_t len, const char *name, hr_from_json_fn fn,
                           void *out, hearth_err *err) {
  hj_ctx c;
  hj_init(&c, name, err);
  json_t *root;
  hearth_status s = hj_load(&c, text, len, &root);
  if (s) return s;
  s = fn(&c, root, out);
  json_decref(root);
  return s;
}

hearth_status hr_read_doc(const char *path, hr_from_json_fn fn, void *out, hearth_err *err) {
  char *text;
  size_t len;
  hearth_status s = hj_read_text(path, &text, &len, err);
  if (s) return s;
  s = hr_parse_doc(text, len, path, fn, out, err);
  free(text);
  return s;
}

/* a required string that must be non-empty */
hearth_status hr_get_nonempty(hj_ctx *c, const json_t *obj, const char *key, char *buf,
                              size_t bufsz) {
  hearth_status s = hj_get_string(c, obj, key, buf, bufsz);
  if (s) return s;
  if (!buf[0]) {
    size_t m = hj_push_key(c, key);
    s = hj_fail(c, HEARTH_E_RANGE, "expected a non-empty string");
    hj_pop(c, m);
  }
  return s;
}

/* a required string that passes check(), with a description of what passes */
hearth_status hr_get_checked(hj_ctx *c, const json_t *obj, const char *key, char *buf, size_t bufsz,
                             int (*check)(const char *), const char *expected) {
  hearth_status s = hj_get_string(c, obj, key, buf, bufsz);
  if (s) return s;
  if (!check(buf)) {
    size_t m = hj_push_key(c, key);
    s = hj_fail(c, HEARTH_E_RANGE, "expected %s, found \"%s\"", expected, buf);
    hj_pop(c, m);
  }
  return s;
}

typedef struct hr_keyed {
  const char *a, *b;
  size_t i;
} hr_keyed;

static int hr_keyed_cmp(const void *pa, const void *pb) {
  const hr_keyed *x = pa, *y = pb;
  int c = strcmp(x->a, y->a);
  if (!c && x->b && y->b) c = strcmp(x->b, y->b);
  if (!c) c = (x->i > y->i) - (x->i < y->i);
  return c;
}

int hr_find_duplicate(size_t n, hr_key_fn key, const void *ctx, size_t *first, size_t *second) {
  if (n < 2) return 0;
  hr_keyed *k = hearth_alloc_array(n, sizeof *k);
  int found = 0;
  if (!k) {
    /* no memory for the sort: fall back to the quadratic scan */
    for (size_t j = 1; j < n && !found; j++)
      for (size_t i = 0; i < j && !found; i++) {
        const char *a1, *b1, *a2, *b2;
        key(ctx, i, &a1, &b1);
        key(ctx, j, &a2, &b2);
        if (!strcmp(a1, a2) && (!b1 || !b2 || !strcmp(b1, b2))) {
          *first = i;
          *second = j;
          found = 1;
        }
      }
    return found;
  }
  for (size_t i = 0; i < n; i++) {
    key(ctx, i, &k[i].a, &k[i].b);
    k[i].i = i;
  }
  qsort(k, n, sizeof *k, hr_keyed_cmp);
  /* equal keys sit together ordered by index; report the smallest repeat */
  for (size_t j = 1; j < n; j++) {
    int same = !strcmp(k[j].a, k[j - 1].a) && (!k[j].b || !strcmp(k[j].b, k[j - 1].b));
    if (same && (!found || k[j].i < *second)) {
      size_t g = j - 1;
      while (g > 0 && !strcmp(k[g - 1].a, k[j].a) && (!k[j].b || !strcmp(k[g - 1].b, k[j].b))) g--;
      *first = k[g].i;
      *second = k[j].i;
      found = 1;
    }
  }
  free(k);
  return found;
}
