/* From a COLMAP model to hearth's poses and the cameras beside them: view
 * and state names from image names, the order of the views, duplicates. */
#include <stdlib.h>
#include <string.h>

#include "hearth/recon.h"

/* states in the order poses files list them */
static const char *const k_state_order[] = {"neutral", "hot", "warm", "iced", "used"};

static int state_rank(const char *s) {
  for (int i = 0; i < (int)(sizeof k_state_order / sizeof k_state_order[0]); i++)
    if (!strcmp(s, k_state_order[i])) return i;
  return (int)(sizeof k_state_order / sizeof k_state_order[0]);
}

static int view_char_ok(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-';
}

hearth_status hearth_colmap_view_of(const char *image_name, const char *default_state,
                                    char state[HEARTH_NAME_MAX], char view[HEARTH_NAME_MAX],
                                    hearth_err *err) {
  const char *base = strrchr(image_name, '/');
  base = base ? base + 1 : image_name;
  const char *dot = strrchr(base, '.');
  size_t n = dot && dot != base ? (size_t)(dot - base) : strlen(base);
  int ok = n >= 1 && n < HEARTH_NAME_MAX;
  for (size_t i = 0; ok && i < n; i++) ok = view_char_ok(base[i]);
  if (!ok)
    return hearth_err_set(err, HEARTH_E_RANGE,
                          "image \"%s\": its file name's stem is not a view name (1..63 letters, "
                          "digits, '_' or '-')",
                          image_name);
  const char *slash = strchr(image_name, '/');
  char first[HEARTH_NAME_MAX] = "";
  if (slash && (size_t)(slash - image_name) < sizeof first) {
    memcpy(first, image_name, (size_t)(slash - image_name));
    first[slash - image_name] = 0;
  }
  if (hearth_state_valid(first)) {
    memcpy(state, first, strlen(first) + 1);
  } else {
    if (!default_state || !hearth_state_valid(default_state))
      return hearth_err_set(err, HEARTH_E_RANGE,
                            "image \"%s\": no state folder in its name and the default state \"%s\" "
                            "is not neutral, hot, warm, iced or used",
                            image_name, default_state ? default_state : "");
    snprintf(state, HEARTH_NAME_MAX, "%s", default_state);
  }
  memcpy(view, base, n);
  view[n] = 0;
  return HEARTH_OK;
}

void hearth_recon_cameras_free(hearth_recon_cameras *c) {
  if (!c) return;
  free(c->cameras);
  free(c->views);
  memset(c, 0, sizeof *c);
}

typedef struct pose_key {
  char state[HEARTH_NAME_MAX], view[HEARTH_NAME_MAX];
  int rank;
  size_t image; /* index into the model's images */
} pose_key;

static int pose_key_cmp(const void *pa, const void *pb) {
  const pose_key *a = pa, *b = pb;
  if (a->rank != b->rank) return a->rank < b->rank ? -1 : 1;
  int c = strcmp(a->view, b->view);
  if (c) return c;
  return (a->image > b->image) - (a->image < b->image);
}

hearth_status hearth_colmap_to_poses(const hearth_colmap_model *m, const char *default_state,
                                     hearth_poses *poses, hearth_recon_cameras *cams,
                                     hearth_err *err) {
  memset(poses, 0, sizeof *poses);
  if (cams) memset(cams, 0, sizeof *cams);
  size_t n = m->n_images;
  pose_key *k = hearth_calloc_array(n ? n : 1, sizeof *k);
  if (!k) return hearth_err_set(err, HEARTH_E_NOMEM, "out of memory for %zu views", n);
  hearth_status s = HEARTH_OK;
  for (size_t i = 0; i < n && !s; i++) {
    s = hearth_colmap_view_of(m->images[i].name, default_state, k[i].state, k[i].view, err);
    if (s) hearth_err_prefix(err, "COLMAP image %u", (unsigned)m->images[i].id);
    k[i].rank = state_rank(k[i].state);
    k[i].image = i;
  }
  if (!s) qsort(k, n, sizeof *k, pose_key_cmp);
  for (size_t i = 1; i < n && !s; i++)
    if (!strcmp(k[i].state, k[i - 1].state) && !strcmp(k[i].view, k[i - 1].view))
      s = hearth_err_set(err, HEARTH_E_INCONSISTENT,
                         "COLMAP images %u (\"%s\") and %u (\"%s\") are both view %s of state %s",
                         (unsigned)m->images[k[i - 1].image].id, m->images[k[i - 1].image].name,
                         (unsigned)m->images[k[i].image].id, m->images[k[i].image].name, k[i].view,
                         k[i].state);
  hearth_view_pose *views = NULL;
  hearth_recon_view_camera *vc = NULL;
  hearth_colmap_camera *cc = NULL;
  if (!s) {
    views = hearth_calloc_array(n ? n : 1, sizeof *views);
    if (cams) {
      vc = hearth_calloc_array(n ? n : 1, sizeof *vc);
      cc = hearth_calloc_array(m->n_cameras ? m->n_cameras : 1, sizeof *cc);
    }
    if (!views || (cams && (!vc || !cc)))
      s = hearth_err_set(err, HEARTH_E_NOMEM, "out of memory for %zu views", n);
  }
  if (!s) {
    for (size_t i = 0; i < n; i++) {
      const hearth_colmap_image *im = &m->images[k[i].image];
      memcpy(views[i].state, k[i].state, sizeof views[i].state);
      memcpy(views[i].view, k[i].view, sizeof views[i].view);
      views[i].T_world_from_cam = im->T_world_from_cam;
      if (vc) {
        memcpy(vc[i].state, k[i].state, sizeof vc[i].state);
        memcpy(vc[i].view, k[i].view, sizeof vc[i].view);
        vc[i].camera_id = im->camera_id;
        vc[i].image_id = im->id;
        memcpy(vc[i].image, im->name, sizeof vc[i].image);
      }
    }
    poses->n = n;
    poses->views = views;
    if (cams) {
      if (m->n_cameras) memcpy(cc, m->cameras, m->n_cameras * sizeof *cc);
      cams->n_cameras = m->n_cameras;
      cams->cameras = cc;
      cams->n_views = n;
      cams->views = vc;
    }
  } else {
    free(views);
    free(vc);
    free(cc);
  }
  free(k);
  return s;
}

hearth_status hearth_recon_cameras_path(const char *poses_path, char *buf, size_t bufsz) {
  size_t n = strlen(poses_path);
  if (n >= 5 && !strcmp(poses_path + n - 5, ".json")) n -= 5;
  int w = snprintf(buf, bufsz, "%.*s_cameras.json", (int)n, poses_path);
  return w < 0 || (size_t)w >= bufsz ? HEARTH_E_LIMIT : HEARTH_OK;
}
