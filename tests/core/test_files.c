/* Atomic writes leave nothing half-written; read_file enforces limits. */
#include <dirent.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
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
  char keep[1300];
  /* the temporary pattern, and names that only look like it */
  size_t bl = 0;
  long pid = 0;
  CHECK(hearth_temp_parse("mask.npy.tmp-4711-Ab12Cd", &bl, &pid) && bl == 8 && pid == 4711);
  CHECK(hearth_temp_parse("hot.tmp-1-000000", &bl, &pid) && bl == 3 && pid == 1);
  CHECK(hearth_temp_parse("a.tmp-9-x.tmp-12-Zz9y8X", &bl, &pid) && bl == 9 && pid == 12);
  CHECK(!hearth_temp_parse("mask.npy", NULL, NULL) &&
        !hearth_temp_parse(".tmp-1-Ab12Cd", NULL, NULL));
  CHECK(!hearth_temp_parse("a.tmp-1-Ab12C", NULL, NULL) &&
        !hearth_temp_parse("a.tmp-1-Ab12Cde", NULL, NULL));
  CHECK(!hearth_temp_parse("a.tmp-1-Ab_2Cd", NULL, NULL) &&
        !hearth_temp_parse("a.tmp-Ab12Cd", NULL, NULL));
  CHECK(!hearth_temp_parse("a.tmp--Ab12Cd", NULL, NULL) &&
        !hearth_temp_parse("a.tmp-0-Ab12Cd", NULL, NULL));
  CHECK(!hearth_temp_parse("a.tmp-12345678901-Ab12Cd", NULL, NULL) &&
        !hearth_temp_parse("a.tmp-1-Ab12Cd.png", NULL, NULL) &&
        !hearth_temp_parse("hot.old-4242", NULL, NULL));
  /* temporaries made by the helpers have the pattern and this process's id */
  char tmp[1300];
  int fd = -1;
  CHECK_OK(hearth_temp_file(path, tmp, sizeof tmp, &fd, &err), &err);
  const char *base = strrchr(tmp, '/') + 1;
  CHECK(hearth_temp_parse(base, &bl, &pid) && bl == strlen("a.txt") && pid == (long)getpid());
  CHECK(fd >= 0 && write(fd, "x", 1) == 1);
  close(fd);
  unlink(tmp);
  CHECK_OK(hearth_temp_dir(path, tmp, sizeof tmp, &err), &err);
  base = strrchr(tmp, '/') + 1;
  CHECK(hearth_temp_parse(base, NULL, &pid) && pid == (long)getpid() && hearth_path_exists(tmp));
  rmdir(tmp);
  /* a sweep removes the temporaries of dead writers only, files and whole
     directories, in subdirectories down to the depth asked; a running
     writer's and look-alikes stay */
  pid_t child = fork();
  if (child == 0) _exit(0);
  int wst;
  waitpid(child, &wst, 0);
  long dead = (long)child, live = (long)getpid();
  snprintf(sub, sizeof sub, "%s/sweep", dir);
  char p1[1400];
  snprintf(p1, sizeof p1, "%s/deep/er", sub);
  CHECK_OK(hearth_mkdirs(p1, &err), &err);
  const char *names[] = {"b.npy.tmp-%ld-Ab12Cd", "state.tmp-%ld-AAAAAA/inner", "keep.tmp-1234567",
                         "deep/x.tmp-%ld-q9Z0xY", "deep/er/y.tmp-%ld-q9Z0xY"};
  for (int k = 0; k < 5; k++) {
    char nm[200];
    snprintf(nm, sizeof nm, names[k], dead);
    snprintf(p1, sizeof p1, "%s/%s", sub, nm);
    if (strchr(nm, '/') && k == 1) CHECK_OK(hearth_mkdirs(p1, &err), &err);
    else CHECK_OK(hearth_write_file_atomic(p1, "k", 1, &err), &err);
  }
  snprintf(p1, sizeof p1, "%s/c.png.tmp-%ld-Zz9y8X", sub, live);
  CHECK_OK(hearth_write_file_atomic(p1, "k", 1, &err), &err);
  CHECK(count_entries(sub) == 5); /* b.npy.tmp-, state.tmp-, keep.tmp-, deep, c.png.tmp- */
  size_t removed = 0;
  CHECK_OK(hearth_sweep_temps(sub, "c.png", 0, &removed, &err), &err);
  CHECK(removed == 0 && count_entries(sub) == 5);
  CHECK_OK(hearth_sweep_temps(sub, NULL, 1, &removed, &err), &err);
  CHECK_MSG(removed == 3 && count_entries(sub) == 3, "removed %zu, %d left", removed,
            count_entries(sub));
  snprintf(p1, sizeof p1, "%s/deep/er/y.tmp-%ld-q9Z0xY", sub, dead);
  CHECK(hearth_path_exists(p1));
  removed = 0;
  snprintf(p1, sizeof p1, "%s/deep/er/y", sub);
  CHECK_OK(hearth_sweep_temps_of(p1, &removed, &err), &err);
  CHECK(removed == 1);
  /* an atomic write abandoned by this (running) process is kept */
  snprintf(keep, sizeof keep, "%s/b.npy", sub);
  CHECK_OK(hearth_atomic_open(&af, keep, &err), &err);
  fputs("half", af.fp);
  fflush(af.fp);
  removed = 0;
  CHECK_OK(hearth_sweep_temps(sub, NULL, 0, &removed, &err), &err);
  CHECK(removed == 0 && hearth_path_exists(af.tmp_path));
  hearth_atomic_abort(&af);
  snprintf(keep, sizeof keep, "%s/no-such-dir", dir);
  CHECK_OK(hearth_sweep_temps(keep, NULL, 3, &removed, &err), &err);
  CHECK(removed == 0);
  /* hearth_replace_dir: the old directory goes, nothing is left beside */
  char fin[1400], rep[1400];
  snprintf(fin, sizeof fin, "%s/rep/final", dir);
  snprintf(p1, sizeof p1, "%s/old.txt", fin);
  CHECK_OK(hearth_mkdirs(fin, &err), &err);
  CHECK_OK(hearth_write_file_atomic(p1, "o", 1, &err), &err);
  CHECK_OK(hearth_temp_dir(fin, rep, sizeof rep, &err), &err);
  snprintf(p1, sizeof p1, "%s/new.txt", rep);
  CHECK_OK(hearth_write_file_atomic(p1, "n", 1, &err), &err);
  CHECK_OK(hearth_replace_dir(rep, fin, &err), &err);
  snprintf(p1, sizeof p1, "%s/new.txt", fin);
  CHECK(hearth_path_exists(p1));
  snprintf(p1, sizeof p1, "%s/rep", dir);
  CHECK(count_entries(p1) == 1);
  /* not regular files are refused at once, named and described */
  snprintf(p1, sizeof p1, "%s/fifo", dir);
  CHECK(mkfifo(p1, 0644) == 0);
  CHECK(hearth_read_file(p1, 100, &data, &n, &err) == HEARTH_E_IO);
  CHECK_MSG(strstr(err.msg, "fifo: not a regular file (a FIFO)") != NULL, "%s", err.msg);
  CHECK(hearth_check_regular(p1, &err) == HEARTH_E_IO && strstr(err.msg, "(a FIFO)"));
  CHECK(hearth_read_file(dir, 100, &data, &n, &err) == HEARTH_E_IO &&
        strstr(err.msg, "(a directory)"));
  CHECK(hearth_read_file("/dev/null", 100, &data, &n, &err) == HEARTH_E_IO &&
        strstr(err.msg, "(a character device)"));
  CHECK(hearth_check_regular(path, &err) == HEARTH_OK);
  snprintf(p1, sizeof p1, "%s/nothing", dir);
  CHECK(hearth_check_regular(p1, &err) == HEARTH_E_NOT_FOUND && strstr(err.msg, "missing"));
  /* a write error carries the system's reason */
  CHECK(hearth_write_file_atomic("/proc/self/no-such/x", "x", 1, &err) == HEARTH_E_IO);
  CHECK_MSG(strstr(err.msg, "No such file or directory") != NULL, "%s", err.msg);
  CHECK(hearth_read_file("/nonexistent/file", 10, &data, &n, &err) == HEARTH_E_IO);
  CHECK(strstr(err.msg, "/nonexistent/file") != NULL);
  TEST_MAIN_END();
}
