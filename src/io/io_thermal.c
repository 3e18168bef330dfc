/* Thermal CSVs read against the camera a document describes: a CSV of the
 * wrong size is reported against that document when the CSV itself is a
 * consistent matrix (the camera description is then what disagrees). */
#include <stdio.h>
#include "hearth/thermal.h"

hearth_status hearth_thermal_read_csv_camera(const char *path, size_t width, size_t height,
                                             const char *camera_doc, hearth_image *out,
                                             hearth_err *err) {
  hearth_csv_opts want = {width, height};
  hearth_status s = hearth_thermal_read_csv(path, &want, out, err);
  if (s != HEARTH_E_SIZE || !camera_doc) return s;
  /* the same file read as any consistent rectangle: if that works, the
   * file is a whole matrix of another size */
  hearth_csv_opts any = {0, 0};
  hearth_image img = {0};
  if (hearth_thermal_read_csv(path, &any, &img, NULL) != HEARTH_OK) return s;
  hearth_err_set(err, HEARTH_E_INCONSISTENT,
                 "%s: the thermal camera is %zux%zu, but %s is a %zux%zu matrix (is %s for "
                 "another camera?)",
                 camera_doc, width, height, path, img.width, img.height, camera_doc);
  hearth_image_free(&img);
  return HEARTH_E_INCONSISTENT;
}
