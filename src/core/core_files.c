/* Whole-file reads, atomic writes, temporaries, directories. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "hearth/core.h"

/* what a non-regular file is, for messages ("a FIFO") */
static const char *file_kind(mode_t m) {
  if (S_ISDIR(m)) return "a directory";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISSOCK(m)) return "a socket";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISLNK(m)) return "a symbolic link";
  return "not a file";
}

hearth_status hearth_check_regular(const char *path, hearth_err *err) {
  struct stat st;
  if (stat(path, &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR)
      return hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: missing", path);
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot inspect: %s", path, strerror(errno));
  }
  if (!S_ISREG(st.st_mode))
    return hearth_err_set(err, HEARTH_E_IO, "%s: not a regular file (%s)", path,
                          file_kind(st.st_mode));
  return HEARTH_OK;
}

hearth_status hearth_open_regular(const char *path, int *fd_out, size_t *size, hearth_err *err) {
  *fd_out = -1;
  /* O_NONBLOCK: opening a FIFO for reading would otherwise wait for a
   * writer; the type is checked on the open descriptor (no race with a
   * rename in between), then blocking reads are restored */
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    /* a socket cannot be opened at all (ENXIO): say what it is */
    int e = errno;
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode))
      return hearth_err_set(err, HEARTH_E_IO, "%s: not a regular file (%s)", path,
                            file_kind(st.st_mode));
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot open: %s", path, strerror(e));
  }
  struct stat st;
  if (fstat(fd, &st) != 0) {
    int e = errno;
    close(fd);
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot inspect: %s", path, strerror(e));
  }
  if (!S_ISREG(st.st_mode)) {
    close(fd);
    return hearth_err_set(err, HEARTH_E_IO, "%s: not a regular file (%s)", path,
                          file_kind(st.st_mode));
  }
  int fl = fcntl(fd, F_GETFL);
  if (fl < 0 || fcntl(fd, F_SETFL, fl & ~O_NONBLOCK) != 0) {
    int e = errno;
    close(fd);
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot clear O_NONBLOCK: %s", path, strerror(e));
  }
  if (size) *size = (size_t)st.st_size;
  *fd_out = fd;
  return HEARTH_OK;
}

hearth_status hearth_read_file(const char *path, size_t max_size, uint8_t **data, size_t *size,
                               hearth_err *err) {
  *data = NULL;
  *size = 0;
  int fd;
  size_t n;
  hearth_status s = hearth_open_regular(path, &fd, &n, err);
  if (s) return s;
  if ((uint64_t)n > (uint64_t)max_size) {
    close(fd);
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: %zu bytes exceeds the limit of %zu bytes", path,
                          n, max_size);
  }
  uint8_t *buf = malloc(n + 1);
  if (!buf) {
    close(fd);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot allocate %zu bytes", path, n + 1);
  }
  size_t got = 0;
  while (got < n) {
    ssize_t r = read(fd, buf + got, n - got);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) {
      int e = errno;
      close(fd);
      free(buf);
      return hearth_err_set(err, HEARTH_E_IO, "%s: read failed after %zu of %zu bytes: %s", path,
                            got, n, strerror(e));
    }
    if (r == 0) break;
    got += (size_t)r;
  }
  close(fd);
  if (got != n) {
    free(buf);
    return hearth_err_set(err, HEARTH_E_IO, "%s: short read (%zu of %zu bytes)", path, got, n);
  }
  buf[n] = 0;
  *data = buf;
  *size = n;
  return HEARTH_OK;
}

/* ---- temporaries ------------------------------------------------------------- */
#define TEMP_TAG ".tmp-"
#define TEMP_RANDOM 6

static hearth_status temp_template(const char *final, char *buf, size_t bufsz, hearth_err *err) {
  int n = snprintf(buf, bufsz, "%s" TEMP_TAG "%ld-XXXXXX", final, (long)getpid());
  if (n < 0 || (size_t)n >= bufsz)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: path too long for a temporary name", final);
  return HEARTH_OK;
}

hearth_status hearth_temp_file(const char *final, char *buf, size_t bufsz, int *fd_out,
                               hearth_err *err) {
  if (fd_out) *fd_out = -1;
  hearth_status s = temp_template(final, buf, bufsz, err);
  if (s) return s;
  int fd = mkstemp(buf);
  if (fd < 0) {
    int e = errno;
    buf[0] = 0;
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot create a temporary file: %s", final,
                          strerror(e));
  }
  fchmod(fd, 0644);
  if (fd_out) *fd_out = fd;
  else close(fd);
  return HEARTH_OK;
}

hearth_status hearth_temp_dir(const char *final, char *buf, size_t bufsz, hearth_err *err) {
  hearth_status s = temp_template(final, buf, bufsz, err);
  if (s) return s;
  if (!mkdtemp(buf)) {
    int e = errno;
    buf[0] = 0;
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot create a temporary directory: %s", final,
                          strerror(e));
  }
  chmod(buf, 0755); /* as hearth_mkdirs makes directories (mkdtemp: 0700) */
  return HEARTH_OK;
}

int hearth_temp_parse(const char *name, size_t *base_len, long *pid) {
  const char *t = NULL;
  for (const char *u = strstr(name, TEMP_TAG); u; u = strstr(u + 1, TEMP_TAG)) t = u;
  if (!t || t == name) return 0;
  const char *x = t + strlen(TEMP_TAG);
  long p = 0;
  size_t nd = 0;
  for (; x[nd] >= '0' && x[nd] <= '9'; nd++) {
    if (nd >= 10) return 0;
    p = 10 * p + (x[nd] - '0');
  }
  if (nd == 0 || p <= 0 || x[nd] != '-') return 0;
  const char *r = x + nd + 1;
  size_t nr = 0;
  for (; r[nr]; nr++) {
    char ch = r[nr];
    if (!((ch >= '0' && ch <= '9') || (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z')))
      return 0;
  }
  if (nr != TEMP_RANDOM) return 0;
  if (base_len) *base_len = (size_t)(t - name);
  if (pid) *pid = p;
  return 1;
}

int hearth_temp_writer_alive(long pid) {
  if (pid <= 0 || pid > (long)(~0u >> 1)) return 0;
  if (kill((pid_t)pid, 0) == 0) return 1;
  return errno == EPERM; /* someone else's process: alive */
}

hearth_status hearth_sweep_temps(const char *dir, const char *base, int depth, size_t *n_removed,
                                 hearth_err *err) {
  DIR *d = opendir(dir);
  if (!d) {
    if (errno == ENOENT || errno == ENOTDIR) return HEARTH_OK;
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot list: %s", dir, strerror(errno));
  }
  hearth_status s = HEARTH_OK;
  struct dirent *e;
  char path[4096];
  size_t blen = base ? strlen(base) : 0;
  while (!s && (e = readdir(d))) {
    const char *nm = e->d_name;
    if (!strcmp(nm, ".") || !strcmp(nm, "..")) continue;
    if ((s = hearth_path_join(path, sizeof path, dir, nm))) {
      hearth_err_set(err, s, "%s/%s: path too long", dir, nm);
      break;
    }
    struct stat st;
    size_t bl;
    long pid;
    if (!hearth_temp_parse(nm, &bl, &pid) || (base && (bl != blen || strncmp(nm, base, bl)))) {
      /* only directories are looked at further (the entry's type when the
       * file system gives it, else lstat) */
      int is_dir = e->d_type == DT_DIR ||
                   (e->d_type == DT_UNKNOWN && lstat(path, &st) == 0 && S_ISDIR(st.st_mode));
      if (depth > 0 && is_dir) s = hearth_sweep_temps(path, base, depth - 1, n_removed, err);
      continue;
    }
    if (lstat(path, &st) != 0) continue;
    if (hearth_temp_writer_alive(pid)) continue;
    if (S_ISDIR(st.st_mode)) {
      s = hearth_remove_tree(path, err);
    } else if (unlink(path) != 0 && errno != ENOENT) {
      s = hearth_err_set(err, HEARTH_E_IO, "%s: cannot remove a stale temporary: %s", path,
                         strerror(errno));
    }
    if (!s && n_removed) (*n_removed)++;
  }
  closedir(d);
  return s;
}

hearth_status hearth_sweep_temps_of(const char *final, size_t *n_removed, hearth_err *err) {
  char dir[4096], base[4096];
  size_t n = strlen(final);
  while (n > 1 && final[n - 1] == '/') n--;
  if (n == 0 || n >= sizeof dir)
    return hearth_err_set(err, HEARTH_E_ARG, "%s: bad path for a temporary sweep", final);
  memcpy(dir, final, n);
  dir[n] = 0;
  char *slash = strrchr(dir, '/');
  snprintf(base, sizeof base, "%s", slash ? slash + 1 : dir);
  if (!slash) snprintf(dir, sizeof dir, ".");
  else if (slash == dir) slash[1] = 0;
  else *slash = 0;
  return hearth_sweep_temps(dir, base, 0, n_removed, err);
}

hearth_status hearth_replace_dir(const char *tmp_dir, const char *final_dir, hearth_err *err) {
  char old[4096];
  int had_old = 0;
  hearth_status s;
  if (hearth_path_exists(final_dir)) {
    /* moved onto an empty temporary directory of the pattern (rename
     * replaces an empty directory), so a kill here leaves a sweepable name */
    if ((s = hearth_temp_dir(final_dir, old, sizeof old, err))) return s;
    if (rename(final_dir, old) != 0) {
      int e = errno;
      rmdir(old);
      return hearth_err_set(err, HEARTH_E_IO, "%s: cannot move aside: %s", final_dir, strerror(e));
    }
    had_old = 1;
  }
  if (rename(tmp_dir, final_dir) != 0) {
    int e = errno;
    if (had_old) rename(old, final_dir);
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot rename into place: %s", final_dir,
                          strerror(e));
  }
  if (had_old) return hearth_remove_tree(old, err);
  return HEARTH_OK;
}

/* ---- atomic writes ---------------------------------------------------------------- */
hearth_status hearth_atomic_open(hearth_atomic_file *af, const char *path, hearth_err *err) {
  memset(af, 0, sizeof *af);
  size_t len = strlen(path);
  if (len + 1 > sizeof af->path)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: path too long", path);
  memcpy(af->path, path, len + 1);
  int fd;
  hearth_status s = hearth_temp_file(path, af->tmp_path, sizeof af->tmp_path, &fd, err);
  if (s) {
    af->tmp_path[0] = 0;
    return s;
  }
  af->fp = fdopen(fd, "wb");
  if (!af->fp) {
    int e = errno;
    close(fd);
    unlink(af->tmp_path);
    af->tmp_path[0] = 0;
    return hearth_err_set(err, HEARTH_E_IO, "%s: fdopen failed: %s", path, strerror(e));
  }
  return HEARTH_OK;
}

hearth_status hearth_atomic_commit(hearth_atomic_file *af, hearth_err *err) {
  if (!af->fp) return hearth_err_set(err, HEARTH_E_ARG, "%s: file not open", af->path);
  /* the first failing call's errno is the reason reported; a stream whose
   * earlier write failed reports EIO if the flush does not say more */
  int e = 0;
  if (fflush(af->fp) != 0) e = errno ? errno : EIO;
  else if (ferror(af->fp)) e = EIO;
  if (fclose(af->fp) != 0 && !e) e = errno ? errno : EIO;
  af->fp = NULL;
  if (e) {
    unlink(af->tmp_path);
    af->tmp_path[0] = 0;
    return hearth_err_set(err, HEARTH_E_IO, "%s: write failed: %s", af->path, strerror(e));
  }
  if (rename(af->tmp_path, af->path) != 0) {
    e = errno;
    unlink(af->tmp_path);
    af->tmp_path[0] = 0;
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot rename into place: %s", af->path,
                          strerror(e));
  }
  af->tmp_path[0] = 0;
  return HEARTH_OK;
}

hearth_status hearth_atomic_fail(hearth_atomic_file *af, hearth_err *err) {
  /* a flush retries what is buffered and says why it cannot be written;
   * otherwise the failing call's errno stands */
  int e = errno;
  errno = 0;
  if (af->fp && fflush(af->fp) != 0 && errno) e = errno;
  if (!e) e = EIO;
  hearth_atomic_abort(af);
  return hearth_err_set(err, HEARTH_E_IO, "%s: write failed: %s", af->path, strerror(e));
}

void hearth_atomic_abort(hearth_atomic_file *af) {
  int e = errno; /* kept for a caller that reports it after the abort */
  if (af->fp) {
    fclose(af->fp);
    af->fp = NULL;
  }
  if (af->tmp_path[0]) unlink(af->tmp_path);
  af->tmp_path[0] = 0;
  errno = e;
}

hearth_status hearth_write_file_atomic(const char *path, const void *data, size_t size,
                                       hearth_err *err) {
  hearth_atomic_file af;
  hearth_status s = hearth_atomic_open(&af, path, err);
  if (s) return s;
  errno = 0;
  if (size && fwrite(data, 1, size, af.fp) != size) return hearth_atomic_fail(&af, err);
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
