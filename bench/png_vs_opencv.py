#!/usr/bin/python3
"""Cross-check hearth's PNG/JPEG code against OpenCV (an independent reader
and writer) and time PNG encoding against cv2.imencode in the same run.

usage: /usr/bin/python3 bench/png_vs_opencv.py [BUILD_DIR]

BUILD_DIR (default build) must hold libhearth_io.a and libhearth_core.a.
A small C driver is compiled against them into a temporary directory.
Exit status 0 when every check passes, 1 otherwise, 77 when OpenCV or a C
compiler is missing (skip)."""
import os
import shutil
import subprocess
import sys
import tempfile
import time

try:
    import cv2
    import numpy as np
except ImportError:
    print("skip: python3-opencv / numpy not available")
    sys.exit(77)

DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/image.h"

static int fail(hearth_err *e) { fprintf(stderr, "%s\n", e->msg); return 1; }

int main(int argc, char **argv) {
  hearth_err err = {0};
  hearth_image img;
  if (argc >= 6 && !strcmp(argv[1], "write")) {
    /* write RAW W H C BYTES OUT: raw native samples -> PNG (or JPEG q95) */
    size_t w = strtoul(argv[3], 0, 10), h = strtoul(argv[4], 0, 10);
    int c = atoi(argv[5]), b = atoi(argv[6]);
    if (hearth_image_alloc(&img, w, h, c, (hearth_pixtype)b, &err)) return fail(&err);
    FILE *f = fopen(argv[2], "rb");
    if (!f || fread(img.data, 1, hearth_image_bytes(&img), f) != hearth_image_bytes(&img))
      return 1;
    fclose(f);
    const char *out = argv[7];
    size_t n = strlen(out);
    int jpg = n > 4 && !strcmp(out + n - 4, ".jpg");
    hearth_status s =
        jpg ? hearth_jpeg_write(out, &img, 95, &err) : hearth_png_write(out, &img, &err);
    if (s) return fail(&err);
    hearth_image_free(&img);
    return 0;
  }
  if (argc == 4 && !strcmp(argv[1], "read")) {
    /* read IN OUT: decode -> "W H C BYTES\n" + raw native samples */
    size_t n = strlen(argv[2]);
    int jpg = n > 4 && !strcmp(argv[2] + n - 4, ".jpg");
    hearth_status s =
        jpg ? hearth_jpeg_read(argv[2], &img, &err) : hearth_png_read(argv[2], &img, &err);
    if (s) return fail(&err);
    FILE *f = fopen(argv[3], "wb");
    fprintf(f, "%zu %zu %d %d\n", img.width, img.height, img.channels, (int)img.type);
    fwrite(img.data, 1, hearth_image_bytes(&img), f);
    fclose(f);
    hearth_image_free(&img);
    return 0;
  }
  if (argc == 6 && !strcmp(argv[1], "time")) {
    /* time RAW W H C: best-of-7 PNG encode of a U8 image */
    size_t w = strtoul(argv[3], 0, 10), h = strtoul(argv[4], 0, 10);
    if (hearth_image_alloc(&img, w, h, atoi(argv[5]), HEARTH_PIX_U8, &err)) return fail(&err);
    FILE *f = fopen(argv[2], "rb");
    if (!f || fread(img.data, 1, hearth_image_bytes(&img), f) != hearth_image_bytes(&img))
      return 1;
    fclose(f);
    double best = 1e9;
    size_t size = 0;
    for (int i = 0; i < 7; i++) {
      uint8_t *enc;
      double t0 = hearth_now();
      if (hearth_png_encode(&img, &enc, &size, &err)) return fail(&err);
      double t = hearth_now() - t0;
      if (t < best) best = t;
      free(enc);
    }
    printf("%.3f %zu\n", best * 1e3, size);
    hearth_image_free(&img);
    return 0;
  }
  return 2;
}
"""


def build_driver(build, tmp):
    cc = shutil.which("cc") or shutil.which("gcc")
    if not cc:
        print("skip: no C compiler")
        sys.exit(77)
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    src = os.path.join(tmp, "driver.c")
    with open(src, "w") as f:
        f.write(DRIVER)
    exe = os.path.join(tmp, "driver")
    cmd = [cc, "-O2", "-std=c11", "-I", os.path.join(root, "include"), src,
           os.path.join(build, "libhearth_io.a"), os.path.join(build, "libhearth_core.a"),
           "-lpng", "-lz", "-ljpeg", "-ljansson", "-lm", "-lpthread", "-o", exe]
    subprocess.run(cmd, check=True)
    return exe


def read_dump(path):
    with open(path, "rb") as f:
        head = f.readline().split()
        w, h, c, b = (int(x) for x in head)
        data = f.read()
    dt = np.uint16 if b == 2 else np.uint8
    return np.frombuffer(data, dtype=dt).reshape(h, w, c)


def main():
    build = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else "build")
    failures = 0
    tmp = tempfile.mkdtemp(prefix="hearth-png-bench-")
    try:
        exe = build_driver(build, tmp)
        rng = np.random.default_rng(7)

        def check(name, ok, detail=""):
            nonlocal failures
            print(("ok   " if ok else "FAIL ") + name + (": " + detail if detail else ""))
            if not ok:
                failures += 1

        # hearth writes, OpenCV reads (IMREAD_UNCHANGED keeps 16 bits; BGR order)
        cases = [
            ("u16 gray", rng.integers(0, 65536, (129, 257, 1), dtype=np.uint16)),
            ("u16 rgb", rng.integers(0, 65536, (31, 17, 3), dtype=np.uint16)),
            ("u8 gray", rng.integers(0, 256, (40, 50, 1), dtype=np.uint8)),
            ("u8 rgba", rng.integers(0, 256, (40, 50, 4), dtype=np.uint8)),
        ]
        cases[0][1][0, 0, 0] = 0
        cases[0][1][0, 1, 0] = 65535
        for name, arr in cases:
            raw = os.path.join(tmp, "in.raw")
            arr.tofile(raw)
            out = os.path.join(tmp, name.replace(" ", "_") + ".png")
            h, w, c = arr.shape
            subprocess.run([exe, "write", raw, str(w), str(h), str(c), str(arr.itemsize), out],
                           check=True)
            got = cv2.imread(out, cv2.IMREAD_UNCHANGED)
            if got.ndim == 2:
                got = got[:, :, None]
            elif c == 3:
                got = got[:, :, ::-1]
            elif c == 4:
                got = got[:, :, [2, 1, 0, 3]]
            check("hearth->opencv " + name, got.dtype == arr.dtype and np.array_equal(got, arr))

        # OpenCV writes, hearth reads
        for name, arr in cases:
            path = os.path.join(tmp, "cv_" + name.replace(" ", "_") + ".png")
            c = arr.shape[2]
            if c == 1:
                bgr = arr[:, :, 0]
            else:
                bgr = arr[:, :, ::-1] if c == 3 else arr[:, :, [2, 1, 0, 3]]
            cv2.imwrite(path, np.ascontiguousarray(bgr))
            dump = os.path.join(tmp, "dump.raw")
            subprocess.run([exe, "read", path, dump], check=True)
            check("opencv->hearth " + name, np.array_equal(read_dump(dump), arr))

        # JPEG: hearth q95 file decoded by OpenCV and by hearth agree closely
        y, x = np.mgrid[0:120, 0:160]
        smooth = np.dstack([128 + 90 * np.sin(0.05 * x + 1.3 * k) * np.cos(0.037 * y - 0.4 * k)
                            for k in range(3)]).round().astype(np.uint8)
        raw = os.path.join(tmp, "in.raw")
        smooth.tofile(raw)
        jpg = os.path.join(tmp, "smooth.jpg")
        subprocess.run([exe, "write", raw, "160", "120", "3", "1", jpg], check=True)
        cvj = cv2.imread(jpg, cv2.IMREAD_UNCHANGED)[:, :, ::-1].astype(np.int32)
        dump = os.path.join(tmp, "dump.raw")
        subprocess.run([exe, "read", jpg, dump], check=True)
        hj = read_dump(dump).astype(np.int32)
        mse = np.mean((cvj - smooth.astype(np.int32)) ** 2)
        psnr = 10 * np.log10(255 ** 2 / max(mse, 1e-12))
        check("jpeg q95 PSNR (OpenCV decode) > 35 dB", psnr > 35, "%.2f dB" % psnr)
        check("jpeg decoders agree within 2", int(np.abs(cvj - hj).max()) <= 2,
              "max diff %d" % int(np.abs(cvj - hj).max()))

        # timing: a 1024x1024 RGB texture-like image (smooth field + sensor noise)
        y, x = np.mgrid[0:1024, 0:1024]
        field = 0.5 + 0.25 * np.sin(x * 0.01) + 0.25 * np.cos(y * 0.013 + x * 0.004)
        tex = np.dstack([field * 255, (1 - field) * 200, field * field * 255])
        tex = np.clip(tex + rng.normal(0, 2, tex.shape), 0, 255).astype(np.uint8)
        tex.tofile(raw)
        r = subprocess.run([exe, "time", raw, "1024", "1024", "3"], check=True,
                           capture_output=True, text=True).stdout.split()
        h_ms, h_size = float(r[0]), int(r[1])
        bgr = np.ascontiguousarray(tex[:, :, ::-1])
        best, cv_size = 1e9, 0
        for _ in range(7):
            t0 = time.perf_counter()
            ok, buf = cv2.imencode(".png", bgr)
            best = min(best, time.perf_counter() - t0)
            cv_size = len(buf)
        cv_ms = best * 1e3
        print("png encode 1024x1024 RGB: hearth %.1f ms %d bytes; opencv %.1f ms %d bytes; "
              "time ratio %.2f, size ratio %.2f" % (h_ms, h_size, cv_ms, cv_size, h_ms / cv_ms,
                                                    h_size / cv_size))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print("%d failure(s)" % failures)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
