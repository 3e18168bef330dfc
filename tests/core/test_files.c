/* Atomic writes leave nothing half-written; read_file enforces limits. */
#include <dirent.h>
#include "hearth/core.h"
#include "test_util.h"

static int count_entries(const char *dir) {
  DIR *d = opendir(dir);
  int n = 0;
  struct dirent *e;
  while (d && (e = readdir(d)))
    if (e->d_name[0] != '.') n++;
  if (d) closedir(d);
  return n;
}

int main(void) {
  const char *dir = test_tmpdir("core_files");
  char path[1200], sub[1200];
  hearth_err err = {0};
  snprintf(path, sizeof path, "%s/a.txt", dir);
  CHECK_OK(hearth_write_file_atomic(path, "hello", 5, &err), &err);
  uint8_t *data;
  size_t n;
  CHECK_OK(hearth_read_file(path, 100, &data, &n, &err), &err);
  CHECK(n == 5 && !memcmp(data, "hello", 5) && data[5] == 0);
  free(data);
  CHECK(hearth_read_file(path, 4, &data, &n, &err) == HEARTH_E_LIMIT);
  CHECK(strstr(err.msg, "a.txt") != NULL);
  /* an aborted streamed write leaves the old file and no temporary */
  hearth_atomic_file af;
  CHECK_OK(hearth_atomic_open(&af, path, &err), &err);
  fputs("partial", af.fp);
  hearth_atomic_abort(&af);
  CHECK(count_entries(dir) == 1);
  CHECK_OK(hearth_read_file(path, 100, &data, &n, &err), &err);
  CHECK(n == 5);
  free(data);
  /* writing into a missing directory fails cleanly */
  snprintf(sub, sizeof sub, "%s/missing/b.txt", dir);
  CHECK(hearth_write_file_atomic(sub, "x", 1, &err) == HEARTH_E_IO);
  CHECK(strstr(err.msg, "missing/b.txt") != NULL);
  snprintf(sub, sizeof sub, "%s/x/y/z", dir);
  CHECK_OK(hearth_mkdirs(sub, &err), &err);
  CHECK(hearth_path_exists(sub));
  snprintf(sub, sizeof sub, "%s/x", dir);
  CHECK_OK(hearth_remove_tree(sub, &err), &err);
  CHECK(!hearth_path_exists(sub));
  /* what a killed writer leaves, and names that only look like it */
  CHECK(hearth_is_atomic_temp("mask.npy.tmp-Ab12Cd") && hearth_is_atomic_temp("hot.tmp-000000"));
  CHECK(hearth_is_atomic_temp("a.tmp-x.tmp-Zz9y8X") && hearth_is_atomic_temp("hot.old-4242"));
  CHECK(!hearth_is_atomic_temp("mask.npy") && !hearth_is_atomic_temp(".tmp-Ab12Cd"));
  CHECK(!hearth_is_atomic_temp("a.tmp-Ab12C") && !hearth_is_atomic_temp("a.tmp-Ab12Cde"));
  CHECK(!hearth_is_atomic_temp("a.tmp-Ab_2Cd") && !hearth_is_atomic_temp("a.old-") &&
        !hearth_is_atomic_temp("a.old-12x") && !hearth_is_atomic_temp("a.tmp-Ab12Cd.png"));
  /* a real one, from an atomic write abandoned without abort, is swept with
     a whole temporary directory; other files stay */
  snprintf(sub, sizeof sub, "%s/sweep", dir);
  CHECK_OK(hearth_mkdirs(sub, &err), &err);
  char keep[1300], tdir[1300];
  snprintf(keep, sizeof keep, "%s/keep.tmp-1234567", sub);
  CHECK_OK(hearth_write_file_atomic(keep, "k", 1, &err), &err);
  snprintf(tdir, sizeof tdir, "%s/state.tmp-AAAAAA/inner", sub);
  CHECK_OK(hearth_mkdirs(tdir, &err), &err);
  snprintf(keep, sizeof keep, "%s/b.npy", sub);
  CHECK_OK(hearth_atomic_open(&af, keep, &err), &err);
  fputs("half", af.fp);
  fflush(af.fp);
  CHECK(count_entries(sub) == 3); /* keep.tmp-1234567, state.tmp-AAAAAA, b.npy.tmp-?????? */
  size_t removed = 0;
  CHECK_OK(hearth_remove_stale_temps(sub, &removed, &err), &err);
  CHECK(removed == 2 && count_entries(sub) == 1);
  fclose(af.fp);
  snprintf(keep, sizeof keep, "%s/no-such-dir", dir);
  CHECK_OK(hearth_remove_stale_temps(keep, &removed, &err), &err);
  CHECK(removed == 0);
  CHECK(hearth_read_file("/nonexistent/file", 10, &data, &n, &err) == HEARTH_E_IO);
  CHECK(strstr(err.msg, "/nonexistent/file") != NULL);
  TEST_MAIN_END();
}
