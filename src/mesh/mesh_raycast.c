/* Nearest-hit ray casting on Embree 3. The scene is built once (robust,
 * high quality BVH) and then only read, so concurrent queries are safe. */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/mesh.h"

struct hearth_raycaster {
  RTCDevice device;
  RTCScene scene;
  const hearth_mesh *mesh;
  int ng_sign; /* +1 if Embree's Ng is along (v1-v0)x(v2-v0), -1 if opposite */
};

static int hit_front(const hearth_mesh *m, uint32_t prim, double dx, double dy, double dz);

static const char *rtc_error_name(enum RTCError e) {
  switch (e) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    default: return "unknown error";
  }
}

/* Embree's Ng convention has differed between versions; measure it once:
 * cast a ray at the first non-degenerate triangle and compare Ng with the
 * counter-clockwise normal of whatever triangle it hits. */
static int probe_ng_sign(const hearth_raycaster *rc) {
  const hearth_mesh *m = rc->mesh;
  for (size_t t = 0; t < m->n_triangles && t < 1000; t++) {
    const uint32_t *ix = m->indices + t * 3;
    const float *a = m->positions + (size_t)ix[0] * 3, *b = m->positions + (size_t)ix[1] * 3,
                *c = m->positions + (size_t)ix[2] * 3;
    double e1[3] = {(double)b[0] - a[0], (double)b[1] - a[1], (double)b[2] - a[2]};
    double e2[3] = {(double)c[0] - a[0], (double)c[1] - a[1], (double)c[2] - a[2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                   e1[0] * e2[1] - e1[1] * e2[0]};
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0.0) || !isfinite(len)) continue;
    double size = sqrt(len);
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;
    memset(&rh, 0, sizeof rh);
    /* from just in front of the centroid, straight at it */
    double g[3] = {(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0,
                   (a[2] + b[2] + c[2]) / 3.0};
    rh.ray.org_x = (float)(g[0] + n[0] / len * size);
    rh.ray.org_y = (float)(g[1] + n[1] / len * size);
    rh.ray.org_z = (float)(g[2] + n[2] / len * size);
    rh.ray.dir_x = (float)(-n[0] / len);
    rh.ray.dir_y = (float)(-n[1] / len);
    rh.ray.dir_z = (float)(-n[2] / len);
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = INFINITY;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rc->scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
    double dn = (double)rh.ray.dir_x * rh.hit.Ng_x + (double)rh.ray.dir_y * rh.hit.Ng_y +
                (double)rh.ray.dir_z * rh.hit.Ng_z;
    if (dn == 0.0) continue;
    int front_ccw = hit_front(m, rh.hit.primID, rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z);
    return ((dn < 0.0) == front_ccw) ? 1 : -1;
  }
  return 1;
}

hearth_status hearth_raycaster_new(const hearth_mesh *m, hearth_raycaster **out, hearth_err *err) {
  *out = NULL;
  hearth_status s = hearth_mesh_validate(m, "ray caster mesh", err);
  if (s != HEARTH_OK) return s;
  if (m->n_triangles > (size_t)UINT32_MAX / 3)
    return hearth_err_set(err, HEARTH_E_LIMIT, "ray caster: %zu triangles exceed the 32-bit limit",
                          m->n_triangles);
  hearth_raycaster *rc = calloc(1, sizeof *rc);
  if (!rc) return hearth_err_set(err, HEARTH_E_NOMEM, "ray caster: out of memory");
  rc->mesh = m;
  rc->device = rtcNewDevice(NULL);
  if (!rc->device) {
    enum RTCError e = rtcGetDeviceError(NULL);
    free(rc);
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "ray caster: cannot create Embree device: %s",
                          rtc_error_name(e));
  }
  rc->scene = rtcNewScene(rc->device);
  rtcSetSceneFlags(rc->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(rc->scene, RTC_BUILD_QUALITY_HIGH);
  if (m->n_triangles > 0) {
    RTCGeometry g = rtcNewGeometry(rc->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
    /* Embree owns padded copies of the buffers (it may read 16 bytes past
     * the last vertex) */
    float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                        3 * sizeof(float), m->n_vertices ? m->n_vertices : 1);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           3 * sizeof(unsigned), m->n_triangles);
    if (!vb || !ib) {
      enum RTCError e = rtcGetDeviceError(rc->device);
      rtcReleaseGeometry(g);
      hearth_raycaster_free(rc);
      return hearth_err_set(
          err, HEARTH_E_NOMEM,
          "ray caster: cannot allocate buffers for %zu vertices, %zu triangles: %s", m->n_vertices,
          m->n_triangles, rtc_error_name(e));
    }
    if (m->n_vertices) memcpy(vb, m->positions, m->n_vertices * 3 * sizeof(float));
    for (size_t i = 0; i < m->n_triangles * 3; i++) ib[i] = m->indices[i];
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(rc->scene, g, 0);
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(rc->scene);
  enum RTCError e = rtcGetDeviceError(rc->device);
  if (e != RTC_ERROR_NONE) {
    hearth_raycaster_free(rc);
    return hearth_err_set(err, e == RTC_ERROR_OUT_OF_MEMORY ? HEARTH_E_NOMEM : HEARTH_E_NUMERIC,
                          "ray caster: building the BVH over %zu triangles failed: %s",
                          m->n_triangles, rtc_error_name(e));
  }
  rc->ng_sign = probe_ng_sign(rc);
  *out = rc;
  return HEARTH_OK;
}

void hearth_raycaster_free(hearth_raycaster *rc) {
  if (!rc) return;
  if (rc->scene) rtcReleaseScene(rc->scene);
  if (rc->device) rtcReleaseDevice(rc->device);
  free(rc);
}

/* front = the ray arrives against the counter-clockwise normal
 * (v1 - v0) x (v2 - v0); computed from the mesh so it does not depend on
 * Embree's own normal convention */
static int hit_front(const hearth_mesh *m, uint32_t prim, double dx, double dy, double dz) {
  const uint32_t *t = m->indices + (size_t)prim * 3;
  const float *a = m->positions + (size_t)t[0] * 3, *b = m->positions + (size_t)t[1] * 3,
              *c = m->positions + (size_t)t[2] * 3;
  double e1[3] = {(double)b[0] - a[0], (double)b[1] - a[1], (double)b[2] - a[2]};
  double e2[3] = {(double)c[0] - a[0], (double)c[1] - a[1], (double)c[2] - a[2]};
  double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                 e1[0] * e2[1] - e1[1] * e2[0]};
  return dx * n[0] + dy * n[1] + dz * n[2] < 0.0;
}

/* front from Embree's geometric normal Ng times ng_sign (+1 when Ng points
 * along the counter-clockwise normal); reading Ng avoids a cache miss on
 * the vertex buffer per hit */
static int ng_front(int ng_sign, float nx, float ny, float nz, float dx, float dy, float dz) {
  double d = (double)dx * nx + (double)dy * ny + (double)dz * nz;
  return ng_sign > 0 ? d < 0.0 : d > 0.0;
}

static void no_hit(hearth_ray_hit *hit) {
  hit->t = INFINITY;
  hit->prim = UINT32_MAX;
  hit->b1 = hit->b2 = 0.0f;
  hit->front = 0;
}

/* Embree wants 0 <= tnear <= tfar and finite origin/direction. */
static int ray_ok(float ox, float oy, float oz, float dx, float dy, float dz, float tn, float tf) {
  if (!isfinite(ox) || !isfinite(oy) || !isfinite(oz) || !isfinite(dx) || !isfinite(dy) ||
      !isfinite(dz))
    return 0;
  if (dx == 0.0f && dy == 0.0f && dz == 0.0f) return 0;
  if (isnan(tn) || isnan(tf) || !(tn <= tf)) return 0;
  return 1;
}

int hearth_raycast(const hearth_raycaster *rc, const double org[3], const double dir[3],
                   double tnear, double tfar, hearth_ray_hit *hit) {
  no_hit(hit);
  float tn = (float)(tnear > 0.0 ? tnear : 0.0), tf = (float)tfar;
  float o[3] = {(float)org[0], (float)org[1], (float)org[2]};
  float d[3] = {(float)dir[0], (float)dir[1], (float)dir[2]};
  if (!ray_ok(o[0], o[1], o[2], d[0], d[1], d[2], tn, tf)) return 0;
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  struct RTCRayHit rh;
  memset(&rh, 0, sizeof rh);
  rh.ray.org_x = o[0];
  rh.ray.org_y = o[1];
  rh.ray.org_z = o[2];
  rh.ray.dir_x = d[0];
  rh.ray.dir_y = d[1];
  rh.ray.dir_z = d[2];
  rh.ray.tnear = tn;
  rh.ray.tfar = tf;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(rc->scene, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return 0;
  hit->t = rh.ray.tfar;
  hit->prim = rh.hit.primID;
  hit->b1 = rh.hit.u;
  hit->b2 = rh.hit.v;
  hit->front = ng_front(rc->ng_sign, rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z, d[0], d[1], d[2]);
  return 1;
}

int hearth_raycast_any(const hearth_raycaster *rc, const double org[3], const double dir[3],
                       double tnear, double tfar) {
  float tn = (float)(tnear > 0.0 ? tnear : 0.0), tf = (float)tfar;
  float o[3] = {(float)org[0], (float)org[1], (float)org[2]};
  float d[3] = {(float)dir[0], (float)dir[1], (float)dir[2]};
  if (!ray_ok(o[0], o[1], o[2], d[0], d[1], d[2], tn, tf)) return 0;
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  struct RTCRay ray;
  memset(&ray, 0, sizeof ray);
  ray.org_x = o[0];
  ray.org_y = o[1];
  ray.org_z = o[2];
  ray.dir_x = d[0];
  ray.dir_y = d[1];
  ray.dir_z = d[2];
  ray.tnear = tn;
  ray.tfar = tf;
  ray.mask = 0xFFFFFFFFu;
  /* Embree sets tfar to -inf where the ray is occluded */
  rtcOccluded1(rc->scene, &ctx, &ray);
  return ray.tfar == -INFINITY;
}

typedef struct batch_ctx {
  const hearth_raycaster *rc;
  const float *org, *dir;
  float tnear, tfar;
  hearth_ray_hit *hits;
} batch_ctx;

/* rays [begin, end) in packets of 16; invalid rays are masked out */
static void batch_range(void *vctx, size_t begin, size_t end, int thread_index) {
  const batch_ctx *b = vctx;
  const hearth_raycaster *rc = b->rc;
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  float tn = b->tnear > 0.0f ? b->tnear : 0.0f;
  for (size_t i0 = begin; i0 < end; i0 += 16) {
    size_t n = end - i0 < 16 ? end - i0 : 16;
    _Alignas(64) int valid[16];
    struct RTCRayHit16 rh;
    for (size_t k = 0; k < 16; k++) {
      valid[k] = 0;
      rh.ray.org_x[k] = rh.ray.org_y[k] = rh.ray.org_z[k] = 0.0f;
      rh.ray.dir_x[k] = rh.ray.dir_y[k] = 0.0f;
      rh.ray.dir_z[k] = 1.0f;
      rh.ray.tnear[k] = 0.0f;
      rh.ray.tfar[k] = -INFINITY;
      rh.ray.mask[k] = 0xFFFFFFFFu;
      rh.ray.flags[k] = 0;
      rh.ray.time[k] = 0.0f;
      rh.ray.id[k] = 0;
      rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.primID[k] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    for (size_t k = 0; k < n; k++) {
      const float *o = b->org + (i0 + k) * 3, *d = b->dir + (i0 + k) * 3;
      if (!ray_ok(o[0], o[1], o[2], d[0], d[1], d[2], tn, b->tfar)) continue;
      valid[k] = -1;
      rh.ray.org_x[k] = o[0];
      rh.ray.org_y[k] = o[1];
      rh.ray.org_z[k] = o[2];
      rh.ray.dir_x[k] = d[0];
      rh.ray.dir_y[k] = d[1];
      rh.ray.dir_z[k] = d[2];
      rh.ray.tnear[k] = tn;
      rh.ray.tfar[k] = b->tfar;
    }
    int any = 0;
    for (size_t k = 0; k < n; k++) any |= valid[k];
    if (!any) {
      for (size_t k = 0; k < n; k++) no_hit(b->hits + i0 + k);
      continue;
    }
    /* packets pay off when the directions are nearly parallel (camera or
     * texel-to-camera rays); scattered rays go one at a time (measured
     * faster on a 100k-triangle mesh) */
    int coherent = 1;
    {
      int first = -1;
      double f[3] = {0, 0, 0};
      for (size_t k = 0; k < n && coherent; k++) {
        if (!valid[k]) continue;
        double dx = rh.ray.dir_x[k], dy = rh.ray.dir_y[k], dz = rh.ray.dir_z[k];
        double len2 = dx * dx + dy * dy + dz * dz;
        if (first < 0) {
          double len = sqrt(len2);
          first = (int)k;
          f[0] = dx / len;
          f[1] = dy / len;
          f[2] = dz / len;
        } else {
          /* f . d >= 0.995 |d|, without a square root per ray */
          double dot = f[0] * dx + f[1] * dy + f[2] * dz;
          if (dot < 0 || dot * dot < 0.995 * 0.995 * len2) coherent = 0;
        }
      }
    }
    if (coherent) {
      rtcIntersect16(valid, rc->scene, &ctx, &rh);
    } else {
      struct RTCIntersectContext ctx1;
      rtcInitIntersectContext(&ctx1);
      for (size_t k = 0; k < n; k++) {
        if (!valid[k]) continue;
        struct RTCRayHit r1;
        memset(&r1, 0, sizeof r1);
        r1.ray.org_x = rh.ray.org_x[k];
        r1.ray.org_y = rh.ray.org_y[k];
        r1.ray.org_z = rh.ray.org_z[k];
        r1.ray.dir_x = rh.ray.dir_x[k];
        r1.ray.dir_y = rh.ray.dir_y[k];
        r1.ray.dir_z = rh.ray.dir_z[k];
        r1.ray.tnear = rh.ray.tnear[k];
        r1.ray.tfar = rh.ray.tfar[k];
        r1.ray.mask = 0xFFFFFFFFu;
        r1.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(rc->scene, &ctx1, &r1);
        rh.ray.tfar[k] = r1.ray.tfar;
        rh.hit.geomID[k] = r1.hit.geomID;
        rh.hit.primID[k] = r1.hit.primID;
        rh.hit.u[k] = r1.hit.u;
        rh.hit.v[k] = r1.hit.v;
        rh.hit.Ng_x[k] = r1.hit.Ng_x;
        rh.hit.Ng_y[k] = r1.hit.Ng_y;
        rh.hit.Ng_z[k] = r1.hit.Ng_z;
      }
    }
    for (size_t k = 0; k < n; k++) {
      hearth_ray_hit *h = b->hits + i0 + k;
      if (!valid[k] || rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
        no_hit(h);
        continue;
      }
      h->t = rh.ray.tfar[k];
      h->prim = rh.hit.primID[k];
      h->b1 = rh.hit.u[k];
      h->b2 = rh.hit.v[k];
      h->front = ng_front(rc->ng_sign, rh.hit.Ng_x[k], rh.hit.Ng_y[k], rh.hit.Ng_z[k],
                          rh.ray.dir_x[k], rh.ray.dir_y[k], rh.ray.dir_z[k]);
    }
  }
}

/* parallel driver over whole packets of 16 rays */
typedef struct packet_ctx {
  batch_ctx *b;
  size_t n;
} packet_ctx;

static void batch_packets(void *vctx, size_t begin, size_t end, int thread_index) {
  const packet_ctx *p = vctx;
  size_t lo = begin * 16, hi = end * 16 < p->n ? end * 16 : p->n;
  batch_range(p->b, lo, hi, thread_index);
}

void hearth_raycast_batch(const hearth_raycaster *rc, size_t n, const float *org, const float *dir,
                          float tnear, float tfar, hearth_ray_hit *hits) {
  hearth_raycast_batch_mt(rc, n, org, dir, tnear, tfar, hits, 0);
}

void hearth_raycast_batch_mt(const hearth_raycaster *rc, size_t n, const float *org,
                             const float *dir, float tnear, float tfar, hearth_ray_hit *hits,
                             int nthreads) {
  batch_ctx b = {rc, org, dir, tnear, tfar, hits};
  /* each ray's result depends only on the ray, so the output is the same
   * for any thread count; small batches stay on the calling thread */
  if (n < 8192 || nthreads == 1) {
    batch_range(&b, 0, n, 0);
    return;
  }
  packet_ctx p = {&b, n};
  hearth_parallel_for((n + 15) / 16, nthreads, batch_packets, &p);
}
