/* Whole-file reads, atomic writes, directories. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "hearth/core.h"

hearth_status hearth_read_file(const char *path, size_t max_size, uint8_t **data, size_t *size,
                               hearth_err *err) {
  *data = NULL;
  *size = 0;
  FILE *f = fopen(path, "rb");
  if (!f) return hearth_err_set(err, HEARTH_E_IO, "%s: cannot open: %s", path, strerror(errno));
  struct stat st;
  if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode)) {
    fclose(f);
    return hearth_err_set(err, HEARTH_E_IO, "%s: not a regular file", path);
  }
  if ((uint64_t)st.st_size > (uint64_t)max_size) {
    fclose(f);
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: %lld bytes exceeds the limit of %zu bytes",
                          path, (long long)st.st_size, max_size);
  }
  size_t n = (size_t)st.st_size;
  uint8_t *buf = malloc(n + 1);
  if (!buf) {
    fclose(f);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot allocate %zu bytes", path, n + 1);
  }
  size_t got = n ? fread(buf, 1, n, f) : 0;
  int bad = ferror(f);
  fclose(f);
  if (got != n || bad) {
    free(buf);
    return hearth_err_set(err, HEARTH_E_IO, "%s: short read (%zu of %zu bytes)", path, got, n);
  }
  buf[n] = 0;
  *data = buf;
  *size = n;
  return HEARTH_OK;
}

hearth_status hearth_atomic_open(hearth_atomic_file *af, const char *path, hearth_err *err) {
  memset(af, 0, sizeof *af);
  size_t len = strlen(path);
  if (len + 1 > sizeof af->path || len + 32 > sizeof af->tmp_path)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: path too long", path);
  memcpy(af->path, path, len + 1);
  snprintf(af->tmp_path, sizeof af->tmp_path, "%s.tmp-XXXXXX", path);
  int fd = mkstemp(af->tmp_path);
  if (fd < 0)
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot create temporary file: %s", path,
                          strerror(errno));
  fchmod(fd, 0644);
  af->fp = fdopen(fd, "wb");
  if (!af->fp) {
    close(fd);
    unlink(af->tmp_path);
    return hearth_err_set(err, HEARTH_E_IO, "%s: fdopen failed: %s", path, strerror(errno));
  }
  return HEARTH_OK;
}

hearth_status hearth_atomic_commit(hearth_atomic_file *af, hearth_err *err) {
  if (!af->fp) return hearth_err_set(err, HEARTH_E_ARG, "%s: file not open", af->path);
  int bad = ferror(af->fp);
  if (fflush(af->fp) != 0) bad = 1;
  if (fclose(af->fp) != 0) bad = 1;
  af->fp = NULL;
  if (bad) {
    unlink(af->tmp_path);
    return hearth_err_set(err, HEARTH_E_IO, "%s: write failed: %s", af->path, strerror(errno));
  }
  if (rename(af->tmp_path, af->path) != 0) {
    int e = errno;
    unlink(af->tmp_path);
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot rename into place: %s", af->path,
                          strerror(e));
  }
  return HEARTH_OK;
}

void hearth_atomic_abort(hearth_atomic_file *af) {
  if (af->fp) {
    fclose(af->fp);
    af->fp = NULL;
  }
  if (af->tmp_path[0]) unlink(af->tmp_path);
  af->tmp_path[0] = 0;
}

/* the suffix after the last occurrence of tag in name, NULL without one or
 * when tag starts the name */
static const char *suffix_after(const char *name, const char *tag) {
  const char *t = strstr(name, tag);
  if (!t || t == name) return NULL;
  for (const char *u; (u = strstr(t + 1, tag));) t = u;
  return t + strlen(tag);
}

int hearth_is_atomic_temp(const char *name) {
  const char *x = suffix_after(name, ".tmp-");
  if (x) {
    size_t n = 0;
    for (; x[n]; n++) {
      char ch = x[n];
      if (!((ch >= '0' && ch <= '9') || (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z')))
        return 0;
    }
    return n == 6;
  }
  if ((x = suffix_after(name, ".old-"))) {
    size_t n = 0;
    for (; x[n]; n++)
      if (x[n] < '0' || x[n] > '9') return 0;
    return n >= 1 && n <= 10;
  }
  return 0;
}

hearth_status hearth_remove_stale_temps(const char *dir, size_t *n_removed, hearth_err *err) {
  if (n_removed) *n_removed = 0;
  DIR *d = opendir(dir);
  if (!d) {
    if (errno == ENOENT || errno == ENOTDIR) return HEARTH_OK;
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot list: %s", dir, strerror(errno));
  }
  hearth_status s = HEARTH_OK;
  struct dirent *e;
  char path[4096];
  while ((e = readdir(d))) {
    if (!hearth_is_atomic_temp(e->d_name)) continue;
    if ((s = hearth_path_join(path, sizeof path, dir, e->d_name))) {
      hearth_err_set(err, s, "%s/%s: path too long", dir, e->d_name);
      break;
    }
    struct stat st;
    if (lstat(path, &st) != 0) continue;
    if (S_ISDIR(st.st_mode)) {
      if ((s = hearth_remove_tree(path, err))) break;
    } else if (!S_ISREG(st.st_mode)) {
      continue;
    } else if (unlink(path) != 0 && errno != ENOENT) {
      s = hearth_err_set(err, HEARTH_E_IO, "%s: cannot remove a stale temporary file: %s", path,
                         strerror(errno));
      break;
    }
    if (n_removed) (*n_removed)++;
  }
  closedir(d);
  return s;
}

hearth_status hearth_write_file_atomic(const char *path, const void *data, size_t size,
                                       hearth_err *err) {
  hearth_atomic_file af;
  hearth_status s = hearth_atomic_open(&af, path, err);
  if (s) return s;
  if (size && fwrite(data, 1, size, af.fp) != size) {
    hearth_atomic_abort(&af);
    return hearth_err_set(err, HEARTH_E_IO, "%s: write failed: %s", path, strerror(errno));
  }
  return hearth_atomic_commit(&af, err);
}

hearth_status hearth_mkdirs(const char *path, hearth_err *err) {
  char buf[4096];
  size_t len = strlen(path);
  if (len == 0 || len >= sizeof buf)
    return hearth_err_set(err, HEARTH_E_ARG, "mkdirs: bad path '%s'", path);
  memcpy(buf, path, len + 1);
  for (size_t i = 1; i <= len; i++) {
    if (buf[i] == '/' || buf[i] == 0) {
      char c = buf[i];
      buf[i] = 0;
      if (mkdir(buf, 0755) != 0 && errno != EEXIST)
        return hearth_err_set(err, HEARTH_E_IO, "%s: cannot create directory: %s", buf,
                              strerror(errno));
      buf[i] = c;
    }
  }
  struct stat st;
  if (stat(path, &st) != 0 || !S_ISDIR(st.st_mode))
    return hearth_err_set(err, HEARTH_E_IO, "%s: not a directory", path);
  return HEARTH_OK;
}

int hearth_path_exists(const char *path) {
  struct stat st;
  return stat(path, &st) == 0;
}

hearth_status hearth_remove_tree(const char *path, hearth_err *err) {
  struct stat st;
  if (lstat(path, &st) != 0) return HEARTH_OK;
  if (S_ISDIR(st.st_mode)) {
    DIR *d = opendir(path);
    if (!d) return hearth_err_set(err, HEARTH_E_IO, "%s: cannot open: %s", path, strerror(errno));
    struct dirent *e;
    hearth_status s = HEARTH_OK;
    while (!s && (e = readdir(d)) != NULL) {
      if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
      char child[4096];
      if (hearth_path_join(child, sizeof child, path, e->d_name)) {
        s = hearth_err_set(err, HEARTH_E_LIMIT, "%s: path too long", path);
        break;
      }
      s = hearth_remove_tree(child, err);
    }
    closedir(d);
    if (s) return s;
    if (rmdir(path) != 0)
      return hearth_err_set(err, HEARTH_E_IO, "%s: cannot remove: %s", path, strerror(errno));
    return HEARTH_OK;
  }
  if (unlink(path) != 0)
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot remove: %s", path, strerror(errno));
  return HEARTH_OK;
}

const char *hearth_path_under(const char *root, const char *path) {
  size_t n = strlen(root);
  while (n > 1 && root[n - 1] == '/') n--;
  if (n && !strncmp(path, root, n) && path[n] == '/') return path + n + 1;
  return path;
}

hearth_status hearth_path_join(char *buf, size_t bufsz, const char *a, const char *b) {
  size_t la = strlen(a);
  int slash = la > 0 && a[la - 1] != '/';
  int n = snprintf(buf, bufsz, "%s%s%s", a, slash ? "/" : "", b);
  if (n < 0 || (size_t)n >= bufsz) return HEARTH_E_LIMIT;
  return HEARTH_OK;
}
