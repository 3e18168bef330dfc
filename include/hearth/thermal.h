/* hearth/thermal.h - area io (src/io/io_csv.c, io_thermal.c): apparent-temperature
 * matrices (thermal CSV).
 *
 * The canonical file is 192 lines of 256 comma-separated decimal numbers in
 * degrees Celsius, no header, native sensor row order; the writer produces
 * only that form. The reader also takes what camera software exports,
 * recognised from the content, never from the file name:
 *
 *   layouts   plain rows of values; a "W,H" size line before them (width
 *             first); an axis-labelled matrix (a corner cell with any label,
 *             e.g. "X/Y", then the column indices 0..W-1, and each row led by
 *             its index 0..H-1: HIKMICRO Analyzer); a frame-labelled matrix
 *             (a first column holding a label such as "Frame 1" on the first
 *             row and nothing below: FLIR exports).
 *   metadata  lines before the matrix that are not numbers (file path,
 *             unit, emissivity, distance, min/max/avg, date): kept as
 *             key/value pairs, never read as data.
 *   cells     ',' ';' or tab separators (found from the last line), one
 *             trailing separator per line, quoted cells, blanks around
 *             cells, scientific notation, decimal commas where the separator
 *             is not ',' or inside quotes.
 *   text      UTF-8 with or without a byte order mark; UTF-16 LE/BE with a
 *             byte order mark; 8-bit code pages (Windows-1252, cp949, GBK,
 *             Shift-JIS...) whose bytes >= 0x80 appear only in labels and
 *             metadata. LF, CRLF or CR line ends.
 *
 * Everything else is refused with the file, line and column and what was
 * expected: NaN, empty cells, ragged rows, a blank line inside the matrix,
 * text after it, numbers before the metadata, a wrong index row or column,
 * a first row or column that reads as indices without the axis labels (is
 * it data?), a size line that disagrees with the matrix, a wrong size,
 * values outside -50..650 degC. Lines count from 1 including header lines;
 * columns count characters from 1 (bytes in an 8-bit code page) at the
 * cell's first non-blank character; a byte order mark is not counted.
 *
 * Units: the matrix must be in degC. A file whose metadata declares another
 * temperature unit (a "unit" line saying degF, K or anything unknown, or
 * values written as e.g. "68 degF" or with a degree sign and F) is refused with
 * HEARTH_E_UNSUPPORTED, never converted: a conversion would change a raw
 * matrix and hide a wrong guess at the unit. Raw matrices are never
 * modified. */
#ifndef HEARTH_THERMAL_H
#define HEARTH_THERMAL_H

#include "hearth/image.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HEARTH_THERMAL_MIN_C (-50.0)
#define HEARTH_THERMAL_MAX_C (650.0)

/* Expected size; 0 means "any consistent rectangle". A file of another size
 * is an error naming both sizes. */
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
hearth_status hearth_thermal_write_csv(const char *path, const hearth_image *temps, int decimals,
                                       hearth_err *err);

/* ---- calibration frames of any camera (src/io/io_frames.c) ----------------- */
/* A thermal calibration frame is a temperature CSV (any layout the CSV
 * reader recognises, any consistent size) or, from cameras without a
 * radiometric export, an 8-/16-bit PNG (grey, grey+alpha, RGB or RGBA) or
 * TIFF (grey or RGB, 8/16-bit unsigned, strips, uncompressed or any
 * compression libtiff decodes). The format is recognised from the first
 * bytes, never the name. Images are not radiometric: their values are kept
 * as stored (colour: the mean of R, G, B; TIFF min-is-white inverted to
 * displayed brightness), so only their pattern means anything. */
typedef enum hearth_frame_kind {
  HEARTH_FRAME_CSV = 0,
  HEARTH_FRAME_PNG8,
  HEARTH_FRAME_PNG16,
  HEARTH_FRAME_TIFF8,
  HEARTH_FRAME_TIFF16
} hearth_frame_kind;
/* "csv", "png8", "png16", "tiff8", "tiff16"; never NULL. */
const char *hearth_frame_kind_name(hearth_frame_kind k);
/* Read a frame into a new 1-channel F32 image (degC for CSV, stored values
 * for images); kind (may be NULL) says which format it was. Errors name
 * the file and, for CSV, the line and column; for TIFF the row. */
hearth_status hearth_frame_read(const char *path, hearth_image *out, hearth_frame_kind *kind,
                                hearth_err *err);
hearth_status hearth_frame_read_mem(const void *data, size_t size, const char *name,
                                    hearth_image *out, hearth_frame_kind *kind, hearth_err *err);

typedef enum hearth_tiff_compression {
  HEARTH_TIFF_NONE = 0,
  HEARTH_TIFF_LZW,
  HEARTH_TIFF_DEFLATE,
  HEARTH_TIFF_PACKBITS
} hearth_tiff_compression;
/* Write a 1-channel U8 or U16 image as a grey TIFF (atomically). */
hearth_status hearth_tiff_write(const char *path, const hearth_image *img,
                                hearth_tiff_compression comp, hearth_err *err);

/* ---- what the reader recognised ------------------------------------------- */
typedef enum hearth_csv_layout {
  HEARTH_CSV_PLAIN = 0, /* rows of values only */
  HEARTH_CSV_SIZE_LINE, /* a "W,H" line, then rows of values */
  HEARTH_CSV_AXIS,      /* corner + column indices 0..W-1, rows led by 0..H-1 */
  HEARTH_CSV_FRAME      /* a label column: "Frame 1" on the first row, empty below */
} hearth_csv_layout;
/* "plain", "size-line", "axis-labelled", "frame-labelled"; never NULL. */
const char *hearth_csv_layout_name(hearth_csv_layout layout);

/* One metadata line: key is its first non-empty cell (a trailing ':' or '='
 * dropped; a lone cell "Key: value" or "Key=value" is split there), value
 * the other non-empty cells joined by one space. Both are NUL-terminated
 * UTF-8: text of an 8-bit code page (which cannot be told from its bytes)
 * and control characters are written as \xNN; each is cut to 255 bytes. */
typedef struct hearth_csv_meta {
  const char *key, *value;
  size_t line;
} hearth_csv_meta;

typedef struct hearth_thermal_info {
  hearth_csv_layout layout;
  size_t width, height;         /* of the matrix read */
  char separator;               /* ',', ';' or '\t' */
  char decimal_mark;            /* '.' or ',' (',' if any value uses one); 0: integers only */
  const char *encoding;         /* "ascii", "utf-8", "utf-8-bom", "utf-16le-bom",
                                * "utf-16be-bom" or "8-bit" (static strings) */
  const char *line_ends;        /* "LF", "CRLF", "CR", "mixed" or "none" (static) */
  size_t first_line, last_line; /* the matrix, index row or label row included */
  size_t header_lines;          /* lines before first_line (metadata, blanks, size line) */
  size_t size_line;             /* line of the "W,H" size line; 0 if none */
  const char *label;            /* the axis corner or frame label; NULL for others */
  const char *unit;             /* "degC" if the metadata says so; NULL if it does not say */
  hearth_csv_meta *meta;        /* metadata lines in file order (at most 256 kept) */
  size_t n_meta;
  size_t n_meta_lines; /* metadata lines in the file (may exceed n_meta) */
} hearth_thermal_info;

/* As hearth_thermal_parse_csv / hearth_thermal_read_csv, and when info is
 * not NULL fill it on success (on failure it is left empty). The caller
 * owns info's strings and arrays and releases them with
 * hearth_thermal_info_free; `encoding` and `line_ends` are static. */
hearth_status hearth_thermal_parse_csv_ex(const char *text, size_t len, const char *name,
                                          const hearth_csv_opts *opts, hearth_image *out,
                                          hearth_thermal_info *info, hearth_err *err);
hearth_status hearth_thermal_read_csv_ex(const char *path, const hearth_csv_opts *opts,
                                         hearth_image *out, hearth_thermal_info *info,
                                         hearth_err *err);
/* Free what info owns and zero it; NULL and zeroed infos are fine. */
void hearth_thermal_info_free(hearth_thermal_info *info);
/* The value of the first metadata key equal to key ignoring ASCII case, or
 * NULL. The string belongs to info. */
const char *hearth_thermal_info_get(const hearth_thermal_info *info, const char *key);

#ifdef __cplusplus
}
#endif
#endif
