/* openpi's LIBERO observations: views rotated and resized with padding,
 * the state vector and the prompt, as one msgpack map. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/eval.h"
#include "hearth/geom.h"
#include "hearth/msgpack.h"

void hearth_eval_resize_with_pad(const uint8_t *in, int w, int h, uint8_t *out, int ow, int oh) {
  memset(out, 0, (size_t)ow * oh * 3);
  double ratio = fmax((double)w / ow, (double)h / oh);
  int rw = (int)(w / ratio), rh = (int)(h / ratio);
  if (rw < 1) rw = 1;
  if (rh < 1) rh = 1;
  int x0 = (ow - rw) / 2, y0 = (oh - rh) / 2;
  double sx = (double)w / rw, sy = (double)h / rh;
  for (int y = 0; y < rh; y++) {
    /* pixel centres: half-pixel convention */
    double fy = (y + 0.5) * sy - 0.5;
    if (fy < 0) fy = 0;
    if (fy > h - 1) fy = h - 1;
    int ya = (int)fy, yb = ya + 1 < h ? ya + 1 : ya;
    double ty = fy - ya;
    for (int x = 0; x < rw; x++) {
      double fx = (x + 0.5) * sx - 0.5;
      if (fx < 0) fx = 0;
      if (fx > w - 1) fx = w - 1;
      int xa = (int)fx, xb = xa + 1 < w ? xa + 1 : xa;
      double tx = fx - xa;
      for (int c = 0; c < 3; c++) {
        double v = (1 - ty) * ((1 - tx) * in[3 * ((size_t)ya * w + xa) + c] +
                               tx * in[3 * ((size_t)ya * w + xb) + c]) +
                   ty * ((1 - tx) * in[3 * ((size_t)yb * w + xa) + c] +
                         tx * in[3 * ((size_t)yb * w + xb) + c]);
        int q = (int)lround(v);
        out[3 * ((size_t)(y + y0) * ow + x + x0) + c] = (uint8_t)(q < 0 ? 0 : q > 255 ? 255 : q);
      }
    }
  }
}

/* rotate 180 degrees (OpenGL rows -> openpi's LIBERO convention), resize */
static hearth_status put_image(hearth_mp_writer *w, const char *key, const uint8_t *img, int iw,
                               int ih, int size, hearth_err *err) {
  size_t n = (size_t)iw * ih * 3;
  uint8_t *rot = malloc(n), *out = malloc((size_t)size * size * 3);
  if (!rot || !out) {
    free(rot), free(out);
    return hearth_err_set(err, HEARTH_E_NOMEM, "eval: image buffers");
  }
  for (size_t k = 0; k < (size_t)iw * ih; k++)
    memcpy(rot + 3 * k, img + 3 * ((size_t)iw * ih - 1 - k), 3);
  hearth_eval_resize_with_pad(rot, iw, ih, out, size, size);
  size_t shape[3] = {(size_t)size, (size_t)size, 3};
  hearth_mp_put_cstr(w, key);
  hearth_mp_put_ndarray(w, out, (size_t)size * size * 3, "|u1", shape, 3);
  free(rot), free(out);
  return HEARTH_OK;
}

hearth_status hearth_eval_encode_obs(const hearth_sim_obs *obs, const char *prompt, int thermal,
                                     int size, hearth_mp_writer *w, hearth_err *err) {
  if (!obs->eye_in_hand_rgb)
    return hearth_err_set(err, HEARTH_E_ARG, "eval: the wrist view is off");
  hearth_mp_put_map(w, thermal ? 5 : 4);
  hearth_status st =
      put_image(w, "observation/image", obs->agentview_rgb, obs->width, obs->height, size, err);
  if (!st)
    st = put_image(w, "observation/wrist_image", obs->eye_in_hand_rgb, obs->width, obs->height,
                   size, err);
  if (!st && thermal)
    st = put_image(w, "observation/thermal_image", obs->agentview_thermal, obs->width, obs->height,
                   size, err);
  if (st) return st;
  double state[8];
  memcpy(state, obs->ee_pos, 3 * sizeof(double));
  /* continuous axis-angle, as the LeRobot export stores the state */
  const double q_ref[4] = HEARTH_SIM_STATE_QUAT_REF;
  hearth_rotvec_to_axis_angle_near(obs->ee_ori, q_ref, state + 3);
  memcpy(state + 6, obs->gripper_states, 2 * sizeof(double));
  uint8_t le[64];
  for (int k = 0; k < 8; k++) {
    uint64_t u;
    memcpy(&u, &state[k], 8);
    for (int b = 0; b < 8; b++) le[8 * k + b] = (uint8_t)(u >> (8 * b));
  }
  size_t shape[1] = {8};
  hearth_mp_put_cstr(w, "observation/state");
  hearth_mp_put_ndarray(w, le, sizeof le, "<f8", shape, 1);
  hearth_mp_put_cstr(w, "prompt");
  hearth_mp_put_cstr(w, prompt);
  if (w->failed) return hearth_err_set(err, HEARTH_E_NOMEM, "eval: encoding the observation");
  return HEARTH_OK;
}
