/* NPY: round trips, the exact header bytes (derived by hand from the format
 * description, not from the writer), strict header parsing, and numpy itself
 * reading our files and writing files we read. */
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>
#include "hearth/npy.h"
#include "test_util.h"

static uint8_t *slurp(const char *path, size_t *n) {
  uint8_t *d = NULL;
  hearth_err err = {0};
  if (hearth_read_file(path, 1 << 24, &d, n, &err) != HEARTH_OK) return NULL;
  return d;
}

static void test_round_trip(const char *dir) {
  char path[1200];
  hearth_err err = {0};
  float f[2 * 3 * 4];
  uint8_t u[3 * 5 * 2];
  for (int i = 0; i < 24; i++) f[i] = (float)i * 0.25f - 2.0f;
  f[5] = -0.0f;
  f[7] = 1e-40f; /* subnormal */
  for (int i = 0; i < 30; i++) u[i] = (uint8_t)(i * 37);
  struct {
    hearth_npy_dtype dt;
    int ndim;
    size_t shape[4];
    const void *data;
  } cases[] = {
      {HEARTH_NPY_F32, 2, {4, 6}, f},      {HEARTH_NPY_F32, 3, {2, 3, 4}, f},
      {HEARTH_NPY_U8, 2, {6, 5}, u},       {HEARTH_NPY_U8, 3, {3, 5, 2}, u},
      {HEARTH_NPY_F32, 1, {24}, f},        {HEARTH_NPY_F32, 0, {0}, f},
      {HEARTH_NPY_U8, 4, {1, 2, 3, 5}, u}, {HEARTH_NPY_F32, 2, {0, 7}, f},
  };
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    snprintf(path, sizeof path, "%s/rt%zu.npy", dir, c);
    CHECK_OK(hearth_npy_write(path, cases[c].dt, cases[c].ndim, cases[c].shape, cases[c].data,
                              &err),
             &err);
    size_t n = 0;
    uint8_t *raw = slurp(path, &n);
    CHECK(raw != NULL);
    if (raw) {
      /* header size multiple of 64, '\n' just before the data */
      size_t hlen = (size_t)raw[8] | (size_t)raw[9] << 8;
      CHECK((10 + hlen) % 64 == 0);
      CHECK(raw[10 + hlen - 1] == '\n');
    }
    free(raw);
    hearth_npy a;
    CHECK_OK(hearth_npy_read(path, &a, &err), &err);
    CHECK(a.dtype == cases[c].dt && a.ndim == cases[c].ndim);
    size_t count = 1;
    for (int i = 0; i < cases[c].ndim; i++) {
      CHECK(a.shape[i] == cases[c].shape[i]);
      count *= cases[c].shape[i];
    }
    CHECK(hearth_npy_count(&a) == count);
    size_t bytes = count * (cases[c].dt == HEARTH_NPY_F32 ? 4 : 1);
    CHECK(a.data && memcmp(a.data, cases[c].data, bytes) == 0);
    hearth_npy_free(&a);
  }
}

/* float32 (2, 3) holding 0.0 .. 2.5: the whole file, byte by byte.
 * Header dict (59 chars): {'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }
 * 6 magic + 2 version + 2 length + 59 + '\n' = 70 -> padded to 128, so the
 * header length is 118 = 0x76 and there are 118 - 59 - 1 = 58 spaces.
 * 0.5 = 0x3F000000, 1.0 = 0x3F800000, 1.5 = 0x3FC00000, 2.0 = 0x40000000,
 * 2.5 = 0x40200000, stored little-endian. */
static void test_exact_bytes(const char *dir) {
  uint8_t want[128 + 24];
  const char *dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }";
  CHECK(strlen(dict) == 59);
  memcpy(want, "\x93NUMPY\x01\x00\x76\x00", 10);
  memcpy(want + 10, dict, 59);
  memset(want + 69, ' ', 58);
  want[127] = '\n';
  static const uint8_t data[24] = {0, 0, 0,    0,    0, 0, 0, 0x3F, 0, 0, 0x80, 0x3F,
                                   0, 0, 0xC0, 0x3F, 0, 0, 0, 0x40, 0, 0, 0x20, 0x40};
  memcpy(want + 128, data, 24);

  float v[6] = {0.0f, 0.5f, 1.0f, 1.5f, 2.0f, 2.5f};
  size_t shape[2] = {2, 3};
  char path[1200];
  hearth_err err = {0};
  snprintf(path, sizeof path, "%s/exact.npy", dir);
  CHECK_OK(hearth_npy_write(path, HEARTH_NPY_F32, 2, shape, v, &err), &err);
  size_t n = 0;
  uint8_t *got = slurp(path, &n);
  CHECK(got && n == sizeof want && memcmp(got, want, sizeof want) == 0);
  free(got);

  /* uint8 (5,): dict {'descr': '|u1', 'fortran_order': False, 'shape': (5,), } is 57
   * chars; 10 + 57 + 1 = 68 -> 128, header length 118, 60 spaces */
  uint8_t want8[128 + 5];
  const char *dict8 = "{'descr': '|u1', 'fortran_order': False, 'shape': (5,), }";
  CHECK(strlen(dict8) == 57);
  memcpy(want8, "\x93NUMPY\x01\x00\x76\x00", 10);
  memcpy(want8 + 10, dict8, 57);
  memset(want8 + 67, ' ', 60);
  want8[127] = '\n';
  memcpy(want8 + 128, "\x01\x02\x03\xfe\xff", 5);
  size_t shape8[1] = {5};
  snprintf(path, sizeof path, "%s/exact8.npy", dir);
  CHECK_OK(hearth_npy_write(path, HEARTH_NPY_U8, 1, shape8, "\x01\x02\x03\xfe\xff", &err), &err);
  got = slurp(path, &n);
  CHECK(got && n == sizeof want8 && memcmp(got, want8, sizeof want8) == 0);
  free(got);

  /* the hand-made bytes parse back */
  hearth_npy a;
  CHECK_OK(hearth_npy_parse(want, sizeof want, "want", &a, &err), &err);
  CHECK(a.dtype == HEARTH_NPY_F32 && a.ndim == 2 && a.shape[0] == 2 && a.shape[1] == 3);
  CHECK(a.data && ((float *)a.data)[5] == 2.5f);
  hearth_npy_free(&a);
}

/* build a file from a header text: version 1 or 2, header padded with
 * spaces to `pad_to` (0: no padding), then `nbytes` data bytes */
static size_t build(uint8_t *buf, int version, const char *dict, size_t nbytes) {
  size_t pre = version == 2 ? 12 : 10, dl = strlen(dict);
  memcpy(buf, "\x93NUMPY", 6);
  buf[6] = (uint8_t)version;
  buf[7] = 0;
  size_t hlen = dl;
  if (version == 2) {
    buf[8] = (uint8_t)hlen;
    buf[9] = (uint8_t)(hlen >> 8);
    buf[10] = 0;
    buf[11] = 0;
  } else {
    buf[8] = (uint8_t)hlen;
    buf[9] = (uint8_t)(hlen >> 8);
  }
  memcpy(buf + pre, dict, dl);
  for (size_t i = 0; i < nbytes; i++) buf[pre + dl + i] = (uint8_t)(i * 3);
  return pre + dl + nbytes;
}

static void accept(const char *label, int version, const char *dict, size_t nbytes,
                   hearth_npy_dtype dt, int ndim, size_t d0, size_t d1) {
  uint8_t buf[512];
  size_t n = build(buf, version, dict, nbytes);
  hearth_npy a;
  hearth_err err = {0};
  hearth_status s = hearth_npy_parse(buf, n, label, &a, &err);
  CHECK_MSG(s == HEARTH_OK, "%s: %s", label, err.msg);
  if (s == HEARTH_OK) {
    CHECK_MSG(a.dtype == dt && a.ndim == ndim, "%s: dtype %d ndim %d", label, a.dtype, a.ndim);
    if (ndim > 0) CHECK_MSG(a.shape[0] == d0, "%s", label);
    if (ndim > 1) CHECK_MSG(a.shape[1] == d1, "%s", label);
  }
  hearth_npy_free(&a);
}

static void reject(const char *label, const uint8_t *buf, size_t n, hearth_status want,
                   const char *also) {
  hearth_npy a;
  hearth_err err = {0};
  hearth_status s = hearth_npy_parse(buf, n, "maps/depth.npy", &a, &err);
  CHECK_MSG(s == want, "%s: got %s (%s), expected %s", label, hearth_status_name(s), err.msg,
            hearth_status_name(want));
  CHECK_MSG(a.data == NULL, "%s: data left", label);
  CHECK_MSG(strncmp(err.msg, "maps/depth.npy: ", 16) == 0, "%s: '%s'", label, err.msg);
  CHECK_MSG(strstr(err.msg, "expected") != NULL, "%s: no 'expected' in '%s'", label, err.msg);
  if (also) CHECK_MSG(strstr(err.msg, also) != NULL, "%s: '%s' lacks '%s'", label, err.msg, also);
}

static void reject_dict(const char *label, const char *dict, size_t nbytes, hearth_status want,
                        const char *also) {
  uint8_t buf[512];
  size_t n = build(buf, 1, dict, nbytes);
  reject(label, buf, n, want, also);
}

static void test_headers(void) {
  /* accepted spellings */
  accept("numpy", 1, "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }   \n", 24,
         HEARTH_NPY_F32, 2, 2, 3);
  accept("v2", 2, "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }\n", 24,
         HEARTH_NPY_F32, 2, 2, 3);
  accept("no-trailing-comma", 1, "{'descr':'|u1','fortran_order':False,'shape':(4,2)}\n", 8,
         HEARTH_NPY_U8, 2, 4, 2);
  accept("u1", 1, "{'descr': 'u1', 'fortran_order': False, 'shape': (3,), }\n", 3, HEARTH_NPY_U8, 1,
         3, 0);
  accept("<u1", 1, "{'descr': '<u1', 'fortran_order': False, 'shape': (3,), }\n", 3, HEARTH_NPY_U8,
         1, 3, 0);
  accept("order", 1, "{\"shape\": (2,), \"fortran_order\": False, \"descr\": \"<f4\"}\n", 8,
         HEARTH_NPY_F32, 1, 2, 0);
  accept("rank0", 1, "{'descr': '<f4', 'fortran_order': False, 'shape': (), }\n", 4, HEARTH_NPY_F32,
         0, 0, 0);
  accept("trailing-comma-2d", 1, "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 2,), }\n",
         8, HEARTH_NPY_F32, 2, 1, 2);
  accept("py2-long", 1, "{'descr': '<f4', 'fortran_order': False, 'shape': (1L, 2L), }\n", 8,
         HEARTH_NPY_F32, 2, 1, 2);
  accept("zero-size", 1, "{'descr': '<f4', 'fortran_order': False, 'shape': (0, 5), }\n", 0,
         HEARTH_NPY_F32, 2, 0, 5);

  const char *ok = "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }\n";
  uint8_t buf[512];
  size_t n = build(buf, 1, ok, 24);
  /* truncated data, extra data: the message names both byte counts */
  reject("truncated", buf, n - 1, HEARTH_E_SIZE,
         "23 bytes of array data, expected 24 bytes (6 elements of 4 bytes)");
  reject("no-data", buf, n - 24, HEARTH_E_SIZE, "expected 24 bytes");
  uint8_t big[600];
  memcpy(big, buf, n);
  big[n] = 0;
  reject("extra", big, n + 1, HEARTH_E_SIZE, "25 bytes");
  /* truncated inside the preamble or header */
  reject("short-preamble", buf, 9, HEARTH_E_PARSE, NULL);
  reject("short-header", buf, 40, HEARTH_E_PARSE, "past the end");
  reject("empty", buf, 0, HEARTH_E_PARSE, "magic");
  /* bad magic, unsupported version */
  memcpy(big, buf, n);
  big[1] = 'M';
  reject("magic", big, n, HEARTH_E_PARSE, "magic");
  memcpy(big, buf, n);
  big[6] = 3;
  reject("version3", big, n, HEARTH_E_UNSUPPORTED, "3.0");
  big[6] = 1;
  big[7] = 1;
  reject("version1.1", big, n, HEARTH_E_UNSUPPORTED, "1.1");

  reject_dict("fortran", "{'descr': '<f4', 'fortran_order': True, 'shape': (2, 3), }\n", 24,
              HEARTH_E_UNSUPPORTED, "fortran_order");
  reject_dict("f8", "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }\n", 48,
              HEARTH_E_UNSUPPORTED, "'<f8'");
  reject_dict(">f4", "{'descr': '>f4', 'fortran_order': False, 'shape': (2, 3), }\n", 24,
              HEARTH_E_UNSUPPORTED, "'>f4'");
  reject_dict("u2", "{'descr': '<u2', 'fortran_order': False, 'shape': (2, 3), }\n", 12,
              HEARTH_E_UNSUPPORTED, NULL);
  reject_dict("structured", "{'descr': [('a', '<f4')], 'fortran_order': False, 'shape': (2,), }\n",
              8, HEARTH_E_UNSUPPORTED, "structured");
  reject_dict("rank5", "{'descr': '|u1', 'fortran_order': False, 'shape': (1, 1, 1, 1, 1), }\n", 1,
              HEARTH_E_UNSUPPORTED, "rank");
  reject_dict("not-tuple", "{'descr': '<f4', 'fortran_order': False, 'shape': (5), }\n", 20,
              HEARTH_E_PARSE, "(n,)");
  reject_dict("negative", "{'descr': '<f4', 'fortran_order': False, 'shape': (-1,), }\n", 4,
              HEARTH_E_PARSE, NULL);
  reject_dict("leading-zero", "{'descr': '<f4', 'fortran_order': False, 'shape': (01,), }\n", 4,
              HEARTH_E_PARSE, NULL);
  reject_dict("overflow-dim",
              "{'descr': '<f4', 'fortran_order': False, 'shape': (99999999999999999999999,), }\n",
              4, HEARTH_E_LIMIT, NULL);
  reject_dict("overflow-product",
              "{'descr': '<f4', 'fortran_order': False, 'shape': (4294967296, 4294967296), }\n", 4,
              HEARTH_E_LIMIT, NULL);
  reject_dict("overflow-bytes",
              "{'descr': '<f4', 'fortran_order': False, 'shape': (4611686018427387904,), }\n", 4,
              HEARTH_E_LIMIT, NULL);
  reject_dict("missing-key", "{'descr': '<f4', 'shape': (2, 3), }\n", 24, HEARTH_E_PARSE,
              "fortran_order");
  reject_dict("extra-key", "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), 'x': 1, }\n",
              24, HEARTH_E_PARSE, "unknown key");
  reject_dict("dup-key",
              "{'descr': '<f4', 'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }\n", 24,
              HEARTH_E_PARSE, "duplicate");
  reject_dict("no-newline", "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }  ", 24,
              HEARTH_E_PARSE, NULL);
  reject_dict("junk-after", "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }x\n", 24,
              HEARTH_E_PARSE, NULL);
  reject_dict("bool-typo", "{'descr': '<f4', 'fortran_order': false, 'shape': (2, 3), }\n", 24,
              HEARTH_E_PARSE, "True or False");
  reject_dict("not-dict", "['descr', '<f4']\n", 24, HEARTH_E_PARSE, "'{'");
  /* the header byte of the problem is named: 'True' starts at byte 10 + 34 */
  reject_dict("offset", "{'descr': '<f4', 'fortran_order': True, 'shape': (2, 3), }\n", 24,
              HEARTH_E_UNSUPPORTED, "header byte 44");
}

static int dir_entries(const char *dir) {
  DIR *d = opendir(dir);
  if (!d) return -1;
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL)
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
  closedir(d);
  return n;
}

static void test_failing_writes(const char *dir) {
  char sub[1200], path[1300];
  hearth_err err = {0};
  size_t shape[2] = {2, 2};
  float v[4] = {1, 2, 3, 4};
  snprintf(sub, sizeof sub, "%s/w", dir);
  mkdir(sub, 0755);
  snprintf(path, sizeof path, "%s/missing/x.npy", dir);
  CHECK(hearth_npy_write(path, HEARTH_NPY_F32, 2, shape, v, &err) == HEARTH_E_IO);
  CHECK(!hearth_path_exists(path));
  snprintf(path, sizeof path, "%s/x.npy", sub);
  CHECK(hearth_npy_write(path, HEARTH_NPY_F32, 5, shape, v, &err) == HEARTH_E_ARG);
  CHECK(hearth_npy_write(path, (hearth_npy_dtype)9, 2, shape, v, &err) == HEARTH_E_ARG);
  CHECK(hearth_npy_write(path, HEARTH_NPY_F32, 2, shape, NULL, &err) == HEARTH_E_ARG);
  size_t huge[2] = {(size_t)1 << 40, (size_t)1 << 40};
  CHECK(hearth_npy_write(path, HEARTH_NPY_F32, 2, huge, v, &err) == HEARTH_E_LIMIT);
  CHECK(dir_entries(sub) == 0);
  hearth_npy a;
  snprintf(path, sizeof path, "%s/nope.npy", dir);
  CHECK(hearth_npy_read(path, &a, &err) == HEARTH_E_IO);
  CHECK(strstr(err.msg, "nope.npy") != NULL);
}

/* numpy reads what we write, and we read what numpy writes */
static void test_numpy(const char *dir) {
  if (access("/usr/bin/python3", X_OK) != 0 ||
      system("/usr/bin/python3 -c 'import numpy' >/dev/null 2>&1") != 0) {
    printf("note: /usr/bin/python3 with numpy not available; numpy cross-check skipped\n");
    return;
  }
  hearth_err err = {0};
  char path[1200], cmd[4096], line[4096];
  /* ours -> numpy */
  float f[2 * 3 * 4];
  for (int i = 0; i < 24; i++) f[i] = (float)i * 0.125f - 1.0f;
  size_t s3[3] = {2, 3, 4};
  snprintf(path, sizeof path, "%s/ours_f32.npy", dir);
  CHECK_OK(hearth_npy_write(path, HEARTH_NPY_F32, 3, s3, f, &err), &err);
  snprintf(cmd, sizeof cmd,
           "/usr/bin/python3 -c \"import numpy as np; a = np.load('%s'); "
           "print(a.dtype, a.shape, a.flags['C_CONTIGUOUS'], "
           "' '.join(repr(float(x)) for x in a.ravel()))\"",
           path);
  FILE *p = popen(cmd, "r");
  CHECK(p != NULL);
  if (p) {
    CHECK(fgets(line, sizeof line, p) != NULL);
    pclose(p);
    /* parse the values back rather than comparing float spellings */
    CHECK(strncmp(line, "float32 (2, 3, 4) True ", 23) == 0);
    char *q = line + 23;
    for (int i = 0; i < 24; i++) {
      double d = 0;
      size_t len = strcspn(q, " \n");
      CHECK(hearth_parse_double(q, len, 0, &d) == 0);
      CHECK(d == (double)f[i]);
      q += len + (q[len] == ' ');
    }
  }
  uint8_t u[6] = {0, 1, 127, 128, 254, 255};
  size_t s2[2] = {3, 2};
  snprintf(path, sizeof path, "%s/ours_u8.npy", dir);
  CHECK_OK(hearth_npy_write(path, HEARTH_NPY_U8, 2, s2, u, &err), &err);
  snprintf(cmd, sizeof cmd,
           "/usr/bin/python3 -c \"import numpy as np; a = np.load('%s'); "
           "print(a.dtype, a.shape, ' '.join(str(int(x)) for x in a.ravel()))\"",
           path);
  p = popen(cmd, "r");
  CHECK(p != NULL);
  if (p) {
    CHECK(fgets(line, sizeof line, p) != NULL);
    pclose(p);
    CHECK_MSG(strcmp(line, "uint8 (3, 2) 0 1 127 128 254 255\n") == 0, "numpy printed '%s'", line);
  }

  /* numpy -> ours, format 1.0 and 2.0, several shapes */
  snprintf(cmd, sizeof cmd,
           "cd '%s' && /usr/bin/python3 -c \"import numpy as np; "
           "a = (np.arange(60, dtype=np.float32) * 0.5 - 7).reshape(3, 4, 5); "
           "np.save('np_f32.npy', a); "
           "np.save('np_u8.npy', (np.arange(12) * 21 %% 256).astype(np.uint8).reshape(4, 3)); "
           "np.save('np_1d.npy', np.arange(5, dtype=np.float32)); "
           "np.save('np_0d.npy', np.float32(3.5)); "
           "f = open('np_v2.npy', 'wb'); "
           "np.lib.format.write_array(f, a, version=(2, 0)); f.close(); "
           "np.save('np_f64.npy', a.astype(np.float64)); "
           "np.save('np_fortran.npy', np.asfortranarray(a))\"",
           dir);
  CHECK(system(cmd) == 0);
  hearth_npy a;
  const char *f32files[] = {"np_f32.npy", "np_v2.npy"};
  for (int k = 0; k < 2; k++) {
    snprintf(path, sizeof path, "%s/%s", dir, f32files[k]);
    CHECK_OK(hearth_npy_read(path, &a, &err), &err);
    CHECK(a.dtype == HEARTH_NPY_F32 && a.ndim == 3 && a.shape[0] == 3 && a.shape[1] == 4 &&
          a.shape[2] == 5);
    if (a.data)
      for (int i = 0; i < 60; i++) CHECK(((float *)a.data)[i] == (float)i * 0.5f - 7.0f);
    hearth_npy_free(&a);
  }
  snprintf(path, sizeof path, "%s/np_u8.npy", dir);
  CHECK_OK(hearth_npy_read(path, &a, &err), &err);
  CHECK(a.dtype == HEARTH_NPY_U8 && a.ndim == 2 && a.shape[0] == 4 && a.shape[1] == 3);
  if (a.data)
    for (int i = 0; i < 12; i++) CHECK(((uint8_t *)a.data)[i] == (uint8_t)(i * 21 % 256));
  hearth_npy_free(&a);
  snprintf(path, sizeof path, "%s/np_1d.npy", dir);
  CHECK_OK(hearth_npy_read(path, &a, &err), &err);
  CHECK(a.ndim == 1 && a.shape[0] == 5 && a.data && ((float *)a.data)[4] == 4.0f);
  hearth_npy_free(&a);
  snprintf(path, sizeof path, "%s/np_0d.npy", dir);
  CHECK_OK(hearth_npy_read(path, &a, &err), &err);
  CHECK(a.ndim == 0 && hearth_npy_count(&a) == 1 && a.data && ((float *)a.data)[0] == 3.5f);
  hearth_npy_free(&a);
  snprintf(path, sizeof path, "%s/np_f64.npy", dir);
  CHECK(hearth_npy_read(path, &a, &err) == HEARTH_E_UNSUPPORTED);
  snprintf(path, sizeof path, "%s/np_fortran.npy", dir);
  CHECK(hearth_npy_read(path, &a, &err) == HEARTH_E_UNSUPPORTED);
  CHECK(strstr(err.msg, "np_fortran.npy") != NULL);
}

int main(void) {
  const char *dir = test_tmpdir("io_test_npy");
  test_round_trip(dir);
  test_exact_bytes(dir);
  test_headers();
  test_failing_writes(dir);
  test_numpy(dir);
  TEST_MAIN_END();
}
