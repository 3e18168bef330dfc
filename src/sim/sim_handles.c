/* H4's pot of two handles: their collision boxes from the mesh, the two
 * temperature maps (either handle hot, the other cool), the map of the
 * episode put into the model's thermal texture, the temperature at a
 * finger contact (the nearest surface point's texel) and the failure it
 * decides, the handles' grasp points and their boxes in the front view.
 *
 * The pot stands with its handles along the asset's x axis (make_upright
 * puts the long horizontal axis there); the episode turns it a quarter
 * turn, so handle 0 (asset -x) faces world -y (slot A, the image's left)
 * and handle 1 world +y (slot B). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/geom.h"
#include "sim/sim_env.h"
#include "sim/sim_mjcf.h"
#include "sim/sim_robot.h"

/* the handles' temperatures, our choice of field over the asset's map,
 * s = 0 where a handle leaves the body to 1 at its far end: the hot one
 * as if it had stood over the flame, 58 degC falling to 55; the cool one
 * 38 degC falling to 32 (the synth pot's own handles run 40-48 at the root
 * to 32-37 at the end, docs/simulation.md) */
static double handle_profile(int hot, double s) { return hot ? 58.0 - 3.0 * s : 38.0 - 6.0 * s; }

/* the handle (0, 1) a point of the asset frame lies on, -1 the body, and
 * its s */
static int handle_at(const sim_handles *hd, const double p[3], double *s) {
  if (fabs(p[0]) <= hd->rb) return -1;
  int sd = p[0] > 0;
  double t = (fabs(p[0]) - hd->rb) / fmax(hd->lug_reach[sd] - hd->rb, 1e-4);
  *s = t < 0 ? 0 : t > 1 ? 1 : t;
  return sd;
}

/* the body radius of the pot in its asset frame: the largest distance
 * from the axis of the points more than 30 degrees away from the x axis
 * (the handles stand out along x only) */
static double body_radius(const hearth_mesh *me) {
  double rb = 0;
  for (size_t v = 0; v < me->n_vertices; v++) {
    const float *p = me->positions + 3 * v;
    double r = hypot(p[0], p[1]);
    if (fabs(p[1]) > 0.5 * r) rb = fmax(rb, r);
  }
  return rb;
}

/* collision boxes from the mesh: the body up to its shoulder (the highest
 * point at 80% of the radius or more, the lid's edge included), what rises
 * inside that (the lid's dome and knob), and each handle's bounding box
 * from the body's surface out */
static hearth_status handle_geometry(sim_handles *hd, const sim_asset *a, hearth_err *err) {
  const hearth_mesh *me = &a->mesh;
  double rb = body_radius(me), shoulder = 0, inner_top = 0;
  double lo[2][3], hi[2][3];
  int n_lug[2] = {0, 0};
  for (int s = 0; s < 2; s++)
    for (int i = 0; i < 3; i++) lo[s][i] = INFINITY, hi[s][i] = -INFINITY;
  for (size_t v = 0; v < me->n_vertices; v++) {
    const float *p = me->positions + 3 * v;
    double r = hypot(p[0], p[1]);
    if (fabs(p[0]) > rb + 0.002 && fabs(p[1]) < 0.5 * rb) {
      int s = p[0] > 0;
      n_lug[s]++;
      for (int i = 0; i < 3; i++) lo[s][i] = fmin(lo[s][i], p[i]), hi[s][i] = fmax(hi[s][i], p[i]);
    } else if (r >= 0.8 * rb) {
      shoulder = fmax(shoulder, p[2]);
    } else {
      inner_top = fmax(inner_top, p[2]);
    }
  }
  if (n_lug[0] < 3 || n_lug[1] < 3 || !(rb > 0.01) || !(shoulder > 0.01))
    return hearth_err_set(err, HEARTH_E_SIZE,
                          "sim H4: asset %s has no two handles standing out along its long axis",
                          a->instance);
  hd->rb = rb;
  hd->body_half[0] = hd->body_half[1] = rb, hd->body_half[2] = 0.5 * shoulder;
  hd->body_c[0] = hd->body_c[1] = 0, hd->body_c[2] = 0.5 * shoulder;
  hd->has_lid = inner_top > shoulder + 0.002;
  hd->lid_half[0] = hd->lid_half[1] = 0.8 * rb;
  hd->lid_half[2] = 0.5 * (inner_top - shoulder);
  hd->lid_c[0] = hd->lid_c[1] = 0, hd->lid_c[2] = 0.5 * (inner_top + shoulder);
  for (int s = 0; s < 2; s++) {
    double in = rb, out = s ? hi[s][0] : -lo[s][0];
    hd->lug_c[s][0] = (s ? 1 : -1) * 0.5 * (in + out);
    hd->lug_c[s][1] = 0.5 * (lo[s][1] + hi[s][1]);
    hd->lug_c[s][2] = 0.5 * (lo[s][2] + hi[s][2]);
    hd->lug_half[s][0] = 0.5 * (out - in);
    hd->lug_half[s][1] = 0.5 * (hi[s][1] - lo[s][1]);
    hd->lug_half[s][2] = 0.5 * (hi[s][2] - lo[s][2]);
    hd->lug_reach[s] = out;
  }
  return HEARTH_OK;
}

/* 2D distance of p to triangle abc and the clamped barycentrics */
static double tri_dist2d(const double p[2], const double a[2], const double b[2], const double c[2],
                         double w[3]) {
  double v0[2] = {b[0] - a[0], b[1] - a[1]}, v1[2] = {c[0] - a[0], c[1] - a[1]};
  double v2[2] = {p[0] - a[0], p[1] - a[1]};
  double d00 = v0[0] * v0[0] + v0[1] * v0[1], d01 = v0[0] * v1[0] + v0[1] * v1[1];
  double d11 = v1[0] * v1[0] + v1[1] * v1[1], d20 = v2[0] * v0[0] + v2[1] * v0[1];
  double d21 = v2[0] * v1[0] + v2[1] * v1[1], den = d00 * d11 - d01 * d01;
  if (!(fabs(den) > 1e-18)) return INFINITY;
  double wb = (d11 * d20 - d01 * d21) / den, wc = (d00 * d21 - d01 * d20) / den;
  double wa = 1 - wb - wc;
  if (wa >= 0 && wb >= 0 && wc >= 0) {
    w[0] = wa, w[1] = wb, w[2] = wc;
    return 0;
  }
  /* outside: the nearest point of the three edges */
  const double *P[3] = {a, b, c};
  double best = INFINITY;
  for (int e = 0; e < 3; e++) {
    const double *s0 = P[e], *s1 = P[(e + 1) % 3];
    double d[2] = {s1[0] - s0[0], s1[1] - s0[1]}, q[2] = {p[0] - s0[0], p[1] - s0[1]};
    double dd = d[0] * d[0] + d[1] * d[1];
    double t = dd > 0 ? (q[0] * d[0] + q[1] * d[1]) / dd : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    double ex = q[0] - t * d[0], ey = q[1] - t * d[1], dist = sqrt(ex * ex + ey * ey);
    if (dist < best) {
      best = dist;
      w[0] = w[1] = w[2] = 0;
      w[e] = 1 - t, w[(e + 1) % 3] = t;
    }
  }
  return best;
}

/* the two maps: the asset's temperatures with handle k hot and the other
 * cool. Texels whose centre lies within 0.75 texel of a handle triangle in
 * UV space (rows run with v, as in the asset's map) are the handles' */
static hearth_status handle_maps(sim_handles *hd, sim_asset *a, hearth_err *err) {
  hearth_status st = sim_asset_temperatures(a, err);
  if (st) return st;
  const hearth_mesh *me = &a->mesh;
  size_t R = a->temp_R, n = R * R;
  /* per texel: the handle it shows (-1: none) and its s there */
  float *s_of = hearth_alloc_array(n, sizeof(float));
  int8_t *side = malloc(n ? n : 1);
  for (int k = 0; k < 2; k++) hd->temp[k] = hearth_alloc_array(n, sizeof(float));
  if (!s_of || !side || !hd->temp[0] || !hd->temp[1]) {
    free(s_of), free(side);
    return hearth_err_set(err, HEARTH_E_NOMEM, "sim H4: out of memory");
  }
  memset(side, -1, n);
  for (size_t t = 0; t < me->n_triangles; t++) {
    const uint32_t *ix = me->indices + 3 * t;
    double cx = 0;
    for (int j = 0; j < 3; j++) cx += me->positions[3 * ix[j]] / 3.0;
    if (fabs(cx) <= hd->rb) continue;
    int sd = cx > 0;
    double uv[3][2];
    double u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
    for (int j = 0; j < 3; j++) {
      uv[j][0] = me->uvs[2 * ix[j]] * (double)R, uv[j][1] = me->uvs[2 * ix[j] + 1] * (double)R;
      u0 = fmin(u0, uv[j][0]), u1 = fmax(u1, uv[j][0]);
      v0 = fmin(v0, uv[j][1]), v1 = fmax(v1, uv[j][1]);
    }
    long c0 = (long)floor(u0 - 1.5), c1 = (long)ceil(u1 + 1.5);
    long r0 = (long)floor(v0 - 1.5), r1 = (long)ceil(v1 + 1.5);
    for (long r = r0 < 0 ? 0 : r0; r <= r1 && r < (long)R; r++)
      for (long c = c0 < 0 ? 0 : c0; c <= c1 && c < (long)R; c++) {
        double p[2] = {c + 0.5, r + 0.5}, w[3];
        if (tri_dist2d(p, uv[0], uv[1], uv[2], w) > 0.75) continue;
        double x[3] = {0, 0, 0}, s = 0;
        for (int j = 0; j < 3; j++)
          for (int i = 0; i < 3; i++) x[i] += w[j] * me->positions[3 * ix[j] + i];
        if (handle_at(hd, x, &s) < 0) x[0] = (sd ? 1 : -1) * hd->rb, s = 0;
        size_t i = (size_t)r * R + (size_t)c;
        side[i] = (int8_t)sd;
        s_of[i] = (float)s;
      }
  }
  for (int k = 0; k < 2; k++) {
    for (size_t i = 0; i < n; i++) {
      double T = a->temp[i];
      if (side[i] >= 0) T = handle_profile(side[i] == k, s_of[i]);
      hd->temp[k][i] = (float)T;
    }
    st = sim_temp_turbo(hd->temp[k], R, &hd->turbo[k], err);
    if (st) break;
  }
  free(s_of), free(side);
  return st;
}

hearth_status sim_handles_init(hearth_sim_env *e, hearth_err *err) {
  sim_handles *hd = &e->hd;
  sim_asset *a = &e->assets[0];
  hd->texid = -1;
  hearth_status st = handle_geometry(hd, a, err);
  if (!st) st = handle_maps(hd, a, err);
  if (st) return st;
  /* the scene file's texture: handle 1 hot (an even layout) */
  hearth_image_free(&a->thermal);
  hearth_status s2 = hearth_image_alloc(&a->thermal, hd->turbo[1].width, hd->turbo[1].height, 3,
                                        HEARTH_PIX_U8, err);
  if (s2) return s2;
  memcpy(a->thermal.data, hd->turbo[1].data, hd->turbo[1].width * hd->turbo[1].height * 3);
  hd->hot = 1;
  return HEARTH_OK;
}

void sim_handles_free(sim_handles *hd) {
  for (int k = 0; k < 2; k++) {
    free(hd->temp[k]);
    hd->temp[k] = NULL;
    hearth_image_free(&hd->turbo[k]);
  }
}

void sim_handles_mjcf(const hearth_sim_env *e, double friction, hearth_strbuf *b) {
  const sim_handles *hd = &e->hd;
  const char *common = "group=\"4\" contype=\"1\" conaffinity=\"1\" condim=\"4\" rgba=\"1 1 1 0\"";
  struct {
    const char *name;
    const double *c, *h;
  } box[4] = {{"obj0_col", hd->body_c, hd->body_half},
              {"obj0_lid", hd->lid_c, hd->lid_half},
              {"obj0_lug0", hd->lug_c[0], hd->lug_half[0]},
              {"obj0_lug1", hd->lug_c[1], hd->lug_half[1]}};
  for (int i = 0; i < 4; i++) {
    if (i == 1 && !hd->has_lid) continue;
    hearth_strbuf_printf(
        b,
        "<geom name=\"%s\" type=\"box\" size=\"%s %s %s\" pos=\"%s %s %s\" %s friction=\"%s 0.01 "
        "0.0005\"/>\n",
        box[i].name, sim_num(box[i].h[0]).s, sim_num(box[i].h[1]).s, sim_num(box[i].h[2]).s,
        sim_num(box[i].c[0]).s, sim_num(box[i].c[1]).s, sim_num(box[i].c[2]).s, common,
        sim_num(friction).s);
  }
}

hearth_status sim_handles_model(hearth_sim_env *e, hearth_err *err) {
  sim_handles *hd = &e->hd;
  const mjModel *m = e->m;
  int g = e->obj_geom_th[0];
  hd->texid = g >= 0 && m->geom_matid[g] >= 0 ? m->mat_texid[m->geom_matid[g]] : -1;
  size_t R = hd->turbo[1].width;
  if (hd->texid < 0 || m->tex_width[hd->texid] != (int)R || m->tex_height[hd->texid] != (int)R)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "sim H4: the pot's thermal texture is not its %zux%zu map", R, R);
  /* which row order MuJoCo keeps the texture in */
  const uint8_t *tx = m->tex_rgb + m->tex_adr[hd->texid], *px = hd->turbo[1].data;
  if (memcmp(tx, px, 3 * R) == 0 && memcmp(tx + 3 * R * (R - 1), px + 3 * R * (R - 1), 3 * R) == 0)
    hd->flip = 0;
  else if (memcmp(tx, px + 3 * R * (R - 1), 3 * R) == 0) hd->flip = 1;
  else
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "sim H4: the pot's model texture is not its thermal image");
  return HEARTH_OK;
}

void sim_handles_reset(hearth_sim_env *e) {
  sim_handles *hd = &e->hd;
  /* swap 0: the cool handle in slot A (handle 0), so handle 1 is hot */
  int hot = 1 - e->swap;
  if (hot == hd->hot) return;
  hd->hot = hot;
  size_t R = hd->turbo[hot].width;
  uint8_t *tx = e->m->tex_rgb + e->m->tex_adr[hd->texid];
  const uint8_t *px = hd->turbo[hot].data;
  for (size_t y = 0; y < R; y++)
    memcpy(tx + 3 * R * (hd->flip ? R - 1 - y : y), px + 3 * R * y, 3 * R);
  sim_render_texture_changed(e, hd->texid);
}

/* closest point of triangle abc to p (Ericson, Real-Time Collision
 * Detection 5.1.5) as barycentrics w */
static double closest_on_tri(const double p[3], const double a[3], const double b[3],
                             const double c[3], double w[3]) {
  double ab[3], ac[3], ap[3];
  for (int i = 0; i < 3; i++) ab[i] = b[i] - a[i], ac[i] = c[i] - a[i], ap[i] = p[i] - a[i];
  double d1 = hearth_dot3(ab, ap), d2 = hearth_dot3(ac, ap);
  double bp[3], cp[3];
  for (int i = 0; i < 3; i++) bp[i] = p[i] - b[i], cp[i] = p[i] - c[i];
  double d3 = hearth_dot3(ab, bp), d4 = hearth_dot3(ac, bp);
  double d5 = hearth_dot3(ab, cp), d6 = hearth_dot3(ac, cp);
  double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
  if (d1 <= 0 && d2 <= 0) w[0] = 1, w[1] = 0, w[2] = 0;
  else if (d3 >= 0 && d4 <= d3) w[0] = 0, w[1] = 1, w[2] = 0;
  else if (d6 >= 0 && d5 <= d6) w[0] = 0, w[1] = 0, w[2] = 1;
  else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    double v = d1 / (d1 - d3);
    w[0] = 1 - v, w[1] = v, w[2] = 0;
  } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    double v = d2 / (d2 - d6);
    w[0] = 1 - v, w[1] = 0, w[2] = v;
  } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    w[0] = 0, w[1] = 1 - v, w[2] = v;
  } else {
    double den = 1.0 / (va + vb + vc);
    w[1] = vb * den, w[2] = vc * den, w[0] = 1 - w[1] - w[2];
  }
  double q[3], dd = 0;
  for (int i = 0; i < 3; i++) {
    q[i] = w[0] * a[i] + w[1] * b[i] + w[2] * c[i];
    dd += (q[i] - p[i]) * (q[i] - p[i]);
  }
  return dd;
}

double sim_handles_temp_at(const hearth_sim_env *e, const double pw[3]) {
  const sim_handles *hd = &e->hd;
  const mjtNum *bp = e->d->xpos + 3 * e->obj_body[0], *Rb = e->d->xmat + 9 * e->obj_body[0];
  double d[3] = {pw[0] - bp[0], pw[1] - bp[1], pw[2] - bp[2]}, l[3];
  for (int i = 0; i < 3; i++) l[i] = Rb[i] * d[0] + Rb[3 + i] * d[1] + Rb[6 + i] * d[2];
  const hearth_mesh *me = &e->assets[0].mesh;
  double best = INFINITY, bw[3] = {1, 0, 0};
  size_t bt = 0;
  for (size_t t = 0; t < me->n_triangles; t++) {
    double P[3][3], w[3];
    for (int j = 0; j < 3; j++)
      for (int i = 0; i < 3; i++) P[j][i] = me->positions[3 * me->indices[3 * t + j] + i];
    double dd = closest_on_tri(l, P[0], P[1], P[2], w);
    if (dd < best) best = dd, bt = t, memcpy(bw, w, sizeof bw);
  }
  if (!me->n_triangles) return NAN;
  /* on a handle: its field; elsewhere the map's texel there */
  double q[3] = {0, 0, 0}, s = 0;
  for (int j = 0; j < 3; j++)
    for (int i = 0; i < 3; i++) q[i] += bw[j] * me->positions[3 * me->indices[3 * bt + j] + i];
  int lug = handle_at(hd, q, &s);
  if (lug >= 0) return handle_profile(lug == hd->hot, s);
  double u = 0, v = 0;
  for (int j = 0; j < 3; j++) {
    u += bw[j] * me->uvs[2 * me->indices[3 * bt + j]];
    v += bw[j] * me->uvs[2 * me->indices[3 * bt + j] + 1];
  }
  size_t R = e->assets[0].temp_R;
  long c = (long)floor(u * (double)R), r = (long)floor(v * (double)R);
  c = c < 0 ? 0 : c >= (long)R ? (long)R - 1 : c;
  r = r < 0 ? 0 : r >= (long)R ? (long)R - 1 : r;
  const float *T = hd->temp[hd->hot];
  double t = T[(size_t)r * R + (size_t)c];
  if (isfinite(t)) return t;
  /* a texel without surface at a seam: the warmest valued neighbour */
  double w = NAN;
  for (long dr = -1; dr <= 1; dr++)
    for (long dc = -1; dc <= 1; dc++) {
      long rr = r + dr, cc = c + dc;
      if (rr < 0 || cc < 0 || rr >= (long)R || cc >= (long)R) continue;
      double x = T[(size_t)rr * R + (size_t)cc];
      if (isfinite(x) && !(x <= w)) w = x;
    }
  return w;
}

void sim_handles_check(hearth_sim_env *e, double limit_c) {
  const mjData *d = e->d;
  const mjModel *m = e->m;
  double hottest = -INFINITY;
  for (int i = 0; i < d->ncon; i++) {
    int g1 = d->contact[i].geom1, g2 = d->contact[i].geom2;
    int pad = g1 == e->pad_geom[0] || g1 == e->pad_geom[1] || g2 == e->pad_geom[0] ||
              g2 == e->pad_geom[1];
    int pot = m->geom_bodyid[g1] == e->obj_body[0] || m->geom_bodyid[g2] == e->obj_body[0];
    if (!pad || !pot) continue;
    double p[3] = {d->contact[i].pos[0], d->contact[i].pos[1], d->contact[i].pos[2]};
    double T = sim_handles_temp_at(e, p);
    if (isfinite(T) && T > hottest) hottest = T;
  }
  e->hd.finger_max_c = hottest;
  if (hottest > limit_c) {
    e->failed = 1;
    snprintf(e->fail_msg, sizeof e->fail_msg,
             "a finger touched the pot at %.1f degC, above %.0f degC (step %d)", hottest, limit_c,
             e->steps);
  }
}

void sim_handles_grasp_point(const hearth_sim_env *e, int lug, double xyz[3]) {
  const mjtNum *bp = e->d->xpos + 3 * e->obj_body[0], *R = e->d->xmat + 9 * e->obj_body[0];
  const sim_handles *hd = &e->hd;
  /* the pads (2.2 cm along the handle) overhanging the handle's far end
   * by 4 mm, as far from the hot body as a firm pinch allows */
  double out = fmax(hd->lug_reach[lug] - SIM_PAD_HALF_X + 0.004, fabs(hd->lug_c[lug][0]));
  double l[3] = {lug ? out : -out, hd->lug_c[lug][1], hd->lug_c[lug][2]};
  for (int r = 0; r < 3; r++)
    xyz[r] = bp[r] + R[3 * r] * l[0] + R[3 * r + 1] * l[1] + R[3 * r + 2] * l[2];
}

void sim_handles_boxes(const hearth_sim_env *e, int boxes[2][4]) {
  const mjModel *m = e->m;
  const mjData *d = e->d;
  const sim_handles *hd = &e->hd;
  const mjtNum *bp = d->xpos + 3 * e->obj_body[0], *bR = d->xmat + 9 * e->obj_body[0];
  const double *cp = d->cam_xpos + 3 * e->cam_front, *cR = d->cam_xmat + 9 * e->cam_front;
  double f = 0.5 * e->height / tan(0.5 * m->cam_fovy[e->cam_front] * M_PI / 180.0);
  for (int slot = 0; slot < 2; slot++) {
    /* slot A: handle 0 (world -y after the quarter turn) */
    int lug = slot;
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    for (int c = 0; c < 8; c++) {
      /* the handle's outer half */
      double sgn = lug ? 1 : -1;
      double lx = hd->lug_c[lug][0] + sgn * (c & 1 ? 1.0 : 0.0) * hd->lug_half[lug][0];
      double l[3] = {lx, hd->lug_c[lug][1] + (c & 2 ? 1 : -1) * hd->lug_half[lug][1],
                     hd->lug_c[lug][2] + (c & 4 ? 1 : -1) * hd->lug_half[lug][2]};
      double w[3], dir[3], cc[3];
      for (int r = 0; r < 3; r++)
        w[r] = bp[r] + bR[3 * r] * l[0] + bR[3 * r + 1] * l[1] + bR[3 * r + 2] * l[2];
      for (int r = 0; r < 3; r++) dir[r] = w[r] - cp[r];
      for (int r = 0; r < 3; r++) cc[r] = cR[r] * dir[0] + cR[3 + r] * dir[1] + cR[6 + r] * dir[2];
      if (cc[2] > -1e-6) continue;
      double px = 0.5 * e->width + f * cc[0] / -cc[2], py = 0.5 * e->height + f * cc[1] / -cc[2];
      x0 = fmin(x0, px), x1 = fmax(x1, px), y0 = fmin(y0, py), y1 = fmax(y1, py);
    }
    int b[4] = {(int)floor(x0), (int)floor(y0), (int)floor(x1), (int)floor(y1)};
    for (int i = 0; i < 4; i++) {
      int lim = i & 1 ? e->height - 1 : e->width - 1;
      b[i] = b[i] < 0 ? 0 : b[i] > lim ? lim : b[i];
    }
    memcpy(boxes[slot], b, sizeof b);
  }
}
