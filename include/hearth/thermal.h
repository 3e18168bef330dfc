/* hearth/thermal.h - area io (src/io/io_csv.c, io_thermal.c): apparent-temperature
 * matrices (thermal CSV).
 *
 * The canonical file is 192 lines of 256 comma-separated decimal numbers in
 * degrees Celsius, no header, native sensor row order. Readers also accept
 * what camera software exports: header lines before the matrix, ';' or tab
 * separators, quoted values, decimal commas. Anything else (NaN, empty
 * cells, ragged rows, wrong size, values outside -50..650 degC) is rejected
 * with the file, line and column. Raw matrices are never modified. */
#ifndef HEARTH_THERMAL_H
#define HEARTH_THERMAL_H

#include "hearth/image.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HEARTH_THERMAL_MIN_C (-50.0)
#define HEARTH_THERMAL_MAX_C (650.0)

/* Expected size; 0 means "any consistent rectangle". */
typedef struct hearth_csv_opts {
  size_t width, height;
} hearth_csv_opts;
/* Defaults: 256 x 192 (the paper's camera), as with opts == NULL. */
void hearth_csv_opts_default(hearth_csv_opts *o);

/* Read into a new 1-channel F32 image of degC (the caller frees it with
 * hearth_image_free); row r of the image is line r of the matrix. opts may
 * be NULL (expect 256x192). parse reads text[0..len), which need not be
 * NUL-terminated; `name` names it in messages. */
hearth_status hearth_thermal_read_csv(const char *path, const hearth_csv_opts *opts,
                                      hearth_image *out, hearth_err *err);
hearth_status hearth_thermal_parse_csv(const char *text, size_t len, const char *name,
                                       const hearth_csv_opts *opts, hearth_image *out,
                                       hearth_err *err);
/* Read a CSV that must be width x height because a camera document (e.g.
 * "R/calibration/rig.json") says so: as hearth_thermal_read_csv, but a file
 * that is a whole matrix of another size is reported against camera_doc
 * (HEARTH_E_INCONSISTENT, naming both files). */
hearth_status hearth_thermal_read_csv_camera(const char *path, size_t width, size_t height,
                                             const char *camera_doc, hearth_image *out,
                                             hearth_err *err);
/* Write the canonical form of a 1-channel F32 image with `decimals` (0..9)
 * fixed decimals, '.' as the decimal point whatever the locale (atomic). */
hearth_status hearth_thermal_write_csv(const char *path, const hearth_image *temps,
                                       int decimals, hearth_err *err);

#ifdef __cplusplus
}
#endif
#endif
