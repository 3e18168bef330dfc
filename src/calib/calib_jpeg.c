/* Colour captures read straight to luma for detection.
 *
 * A YCbCr JPEG already stores the luma: asking libjpeg for grayscale output
 * returns the Y plane and skips the chroma inverse DCTs, upsampling and the
 * colour conversion, which are most of a full RGB decode. Y is the same
 * 0.299/0.587/0.114 weighting the detector would apply to RGB, without the
 * chroma round trip. As in io_jpeg.c, warnings about damaged data are errors
 * and setjmp sits in a small function whose changing state lives in a
 * caller-owned struct. */
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>
/* jpeglib.h needs size_t and FILE declared first */
#include <stdio.h>
#include <jpeglib.h>
#include "calib/calib_internal.h"

#define LUMA_MAX_FILE_BYTES ((size_t)1 << 30)

typedef struct luma_reader {
  struct jpeg_decompress_struct cinfo;
  struct jpeg_error_mgr pub;
  jmp_buf jump;
  char jmsg[JMSG_LENGTH_MAX + 64];
  const uint8_t *data;
  size_t size;
  hearth_status status;
  char msg[256];
  hearth_image img;
} luma_reader;

static void on_error(j_common_ptr cinfo) {
  luma_reader *r = (luma_reader *)cinfo->client_data;
  if (!r->jmsg[0]) (*cinfo->err->format_message)(cinfo, r->jmsg);
  longjmp(r->jump, 1);
}

static void on_message(j_common_ptr cinfo, int level) {
  if (level < 0) on_error(cinfo);
}

/* 0 on success, 1 after a libjpeg error (r->jmsg), 2 after our checks */
static int luma_decode(luma_reader *r) {
  if (setjmp(r->jump)) return 1;
  /* jpeg_create_decompress keeps err and client_data */
  r->cinfo.client_data = r;
  jpeg_create_decompress(&r->cinfo);
  jpeg_mem_src(&r->cinfo, r->data, (unsigned long)r->size);
  jpeg_read_header(&r->cinfo, TRUE);
  size_t w = r->cinfo.image_width, h = r->cinfo.image_height;
  if (w == 0 || h == 0 || w > HEARTH_IMAGE_MAX_DIM || h > HEARTH_IMAGE_MAX_DIM) {
    r->status = HEARTH_E_LIMIT;
    snprintf(r->msg, sizeof r->msg, "size %zux%zu exceeds the limit of %d per side", w, h,
             HEARTH_IMAGE_MAX_DIM);
    return 2;
  }
  if (r->cinfo.data_precision != 8) {
    r->status = HEARTH_E_UNSUPPORTED;
    snprintf(r->msg, sizeof r->msg, "%d-bit samples: expected 8-bit JPEG",
             r->cinfo.data_precision);
    return 2;
  }
  /* gray and YCbCr give their luma directly; an RGB-coded JPEG is
   * converted by libjpeg with the same weights */
  if (r->cinfo.jpeg_color_space != JCS_GRAYSCALE && r->cinfo.jpeg_color_space != JCS_YCbCr &&
      r->cinfo.jpeg_color_space != JCS_RGB) {
    r->status = HEARTH_E_UNSUPPORTED;
    snprintf(r->msg, sizeof r->msg, "colour space %d (CMYK/YCCK?): expected gray or RGB",
             (int)r->cinfo.jpeg_color_space);
    return 2;
  }
  r->cinfo.out_color_space = JCS_GRAYSCALE;
  /* a small file claiming a huge image is truncated: refuse before allocating */
  if (w * h / 4096 > r->size + 4096) {
    r->status = HEARTH_E_PARSE;
    snprintf(r->msg, sizeof r->msg,
             "size %zux%zu is more than %zu file bytes can hold (truncated?)", w, h, r->size);
    return 2;
  }
  jpeg_start_decompress(&r->cinfo);
  if (r->cinfo.output_components != 1 || r->cinfo.output_width != w ||
      r->cinfo.output_height != h) {
    r->status = HEARTH_E_UNSUPPORTED;
    snprintf(r->msg, sizeof r->msg, "unexpected output layout");
    return 2;
  }
  hearth_err aerr;
  if (hearth_image_alloc(&r->img, w, h, 1, HEARTH_PIX_U8, &aerr) != HEARTH_OK) {
    r->status = aerr.status;
    snprintf(r->msg, sizeof r->msg, "%s", aerr.msg);
    return 2;
  }
  /* several rows per call: libjpeg hands out a whole iMCU row at once */
  JSAMPROW rows[16];
  while (r->cinfo.output_scanline < r->cinfo.output_height) {
    JDIMENSION y = r->cinfo.output_scanline;
    int k = 0;
    for (; k < 16 && y + (JDIMENSION)k < r->cinfo.output_height; k++)
      rows[k] = (JSAMPROW)r->img.data + (size_t)(y + (JDIMENSION)k) * w;
    if (jpeg_read_scanlines(&r->cinfo, rows, (JDIMENSION)k) == 0) {
      r->status = HEARTH_E_PARSE;
      snprintf(r->msg, sizeof r->msg, "image data ends at row %u of %zu", (unsigned)y, h);
      return 2;
    }
  }
  jpeg_finish_decompress(&r->cinfo);
  return 0;
}

hearth_status calib_jpeg_read_luma(const char *path, hearth_image *img, hearth_err *err) {
  memset(img, 0, sizeof *img);
  uint8_t *buf;
  size_t n;
  hearth_status s = hearth_read_file(path, LUMA_MAX_FILE_BYTES, &buf, &n, err);
  if (s) return s;
  if (n < 3 || memcmp(buf, "\xff\xd8\xff", 3) != 0) {
    free(buf);
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: not a JPEG file (bad signature)", path);
  }
  if (n > (size_t)(unsigned long)-1) {
    free(buf);
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: too large", path);
  }
  luma_reader *r = calloc(1, sizeof *r);
  if (!r) {
    free(buf);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot allocate decoder", path);
  }
  r->data = buf;
  r->size = n;
  jpeg_std_error(&r->pub);
  r->pub.error_exit = on_error;
  r->pub.emit_message = on_message;
  r->cinfo.err = &r->pub;
  int rc = luma_decode(r);
  /* safe even if creation failed: the struct was zeroed */
  jpeg_destroy_decompress(&r->cinfo);
  free(buf);
  if (rc == 1)
    s = hearth_err_set(err, HEARTH_E_PARSE, "%s: invalid JPEG: %s", path, r->jmsg);
  else if (rc == 2)
    s = hearth_err_set(err, r->status, "%s: %s", path, r->msg);
  if (s)
    hearth_image_free(&r->img);
  else
    *img = r->img;
  free(r);
  return s;
}
