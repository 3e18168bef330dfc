/* Private to the dataset area: plumbing shared by its documents (dataset_common.c). */
#ifndef HEARTH_DATASET_INTERNAL_H
#define HEARTH_DATASET_INTERNAL_H

#include "hearth/dataset.h"
#include "dataset/dataset_json.h"

/* fill out from a parsed document; on failure leave nothing allocated in out */
typedef hearth_status (*hr_from_json_fn)(hj_ctx *c, const json_t *root, void *out);
hearth_status hr_parse_doc(const char *text, size_t len, const char *name, hr_from_json_fn fn,
                           void *out, hearth_err *err);
hearth_status hr_read_doc(const char *path, hr_from_json_fn fn, void *out, hearth_err *err);

hearth_status hr_get_nonempty(hj_ctx *c, const json_t *obj, const char *key, char *buf,
                              size_t bufsz);
hearth_status hr_get_checked(hj_ctx *c, const json_t *obj, const char *key, char *buf, size_t bufsz,
                             int (*check)(const char *), const char *expected);

/* duplicate detection over n items keyed by one or two strings (b may be
 * NULL): returns 1 and the indices of the earliest repeated pair (first <
 * second, second smallest) if any */
typedef void (*hr_key_fn)(const void *ctx, size_t i, const char **a, const char **b);
int hr_find_duplicate(size_t n, hr_key_fn key, const void *ctx, size_t *first, size_t *second);
void hr_key_release(const void *ctx, size_t i, const char **a, const char **b);

#endif
