/* Geometry from depth: TSDF fusion of analytic sphere depth maps, marching
 * tetrahedra, cleaning, hole filling and simplification, and an end-to-end
 * run on a small virtual-rig release against its true mesh.
 *
 * With arguments ROOT INSTANCE [VOXEL_M [TRIANGLES [TRUNC_M]]] it only
 * reconstructs that instance of an existing release and prints the
 * surface errors (bench/recon_tsdf.sh uses it); RECON_TSDF_DUMP=FILE.glb
 * also writes the mesh. */
#include <float.h>
#include <time.h>
#include "hearth/dataset.h"
#include "hearth/recon_geom.h"
#include "../test_util.h"

#include "recon/mesh_distance.h"
#include "recon/true_visibility.h"

/* ---- analytic sphere --------------------------------------------------- */
#define SPHERE_R 0.05

/* A camera at distance dist from the origin in direction (az, el), looking
 * at the origin, y axis roughly down the world z. */
static void look_at(double az, double el, double dist, hearth_rigid *T) {
  double c[3] = {dist * cos(el) * cos(az), dist * cos(el) * sin(az), dist * sin(el)};
  double z[3] = {-c[0] / dist, -c[1] / dist, -c[2] / dist};
  double up[3] = {0, 0, -1};
  if (fabs(z[2]) > 0.99) up[0] = 1, up[2] = 0;
  /* x = z cross up, y = z cross x */
  double x[3] = {z[1] * up[2] - z[2] * up[1], z[2] * up[0] - z[0] * up[2],
                 z[0] * up[1] - z[1] * up[0]};
  double l = sqrt(dot3(x, x));
  for (int a = 0; a < 3; a++) x[a] /= l;
  double y[3] = {z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]};
  for (int a = 0; a < 3; a++) {
    T->R[3 * a] = x[a];
    T->R[3 * a + 1] = y[a];
    T->R[3 * a + 2] = z[a];
    T->t[a] = c[a];
  }
}

/* Depth (mm) of the sphere seen by cam at pose T; 0 off the sphere. */
static void render_sphere(const hearth_camera *cam, const hearth_rigid *T, hearth_image *img) {
  hearth_err err = {0};
  CHECK_OK(hearth_image_alloc(img, cam->width, cam->height, 1, HEARTH_PIX_U16, &err), &err);
  uint16_t *d = img->data;
  for (int v = 0; v < cam->height; v++)
    for (int u = 0; u < cam->width; u++) {
      double rc[3] = {(u - cam->cx) / cam->fx, (v - cam->cy) / cam->fy, 1.0}, rw[3];
      hearth_rigid_rotate(T, rc, rw);
      /* |c + s rw|^2 = R^2, s the depth along z (rc has z = 1) */
      double b = dot3(T->t, rw), a = dot3(rw, rw), cc = dot3(T->t, T->t) - SPHERE_R * SPHERE_R;
      double disc = b * b - a * cc;
      if (disc < 0) continue;
      double s = (-b - sqrt(disc)) / a;
      if (s > 0) d[(size_t)v * cam->width + u] = (uint16_t)lround(s * 1000.0);
    }
}

static void sphere_stats(const hearth_mesh *m, double *rms_to, double *rms_from) {
  double s = 0;
  for (size_t v = 0; v < m->n_vertices; v++) {
    const float *p = m->positions + 3 * v;
    double r = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
    s += (r - SPHERE_R) * (r - SPHERE_R);
  }
  *rms_to = sqrt(s / (double)m->n_vertices);
  /* sphere samples on a Fibonacci spiral to the nearest triangle */
  tri_grid g;
  tri_grid_build(&g, m, 0.004);
  const int n = 2000;
  s = 0;
  for (int i = 0; i < n; i++) {
    double z = 1.0 - (2.0 * i + 1.0) / n, r = sqrt(1.0 - z * z), ph = i * 2.399963229728653;
    double p[3] = {SPHERE_R * r * cos(ph), SPHERE_R * r * sin(ph), SPHERE_R * z};
    double d = tri_grid_dist(&g, p);
    s += d * d;
  }
  *rms_from = sqrt(s / n);
  tri_grid_free(&g);
}

static void fuse_sphere(hearth_mesh *m, double voxel) {
  hearth_err err = {0};
  hearth_camera cam = {640, 576, 500, 500, 319.5, 287.5, {0}};
  hearth_tsdf vol;
  double lo[3] = {-0.065, -0.065, -0.065}, hi[3] = {0.065, 0.065, 0.065};
  CHECK_OK(hearth_tsdf_init(&vol, lo, hi, voxel, 4 * voxel, &err), &err);
  const double els[3] = {-1.0, 0.0, 1.0};
  for (int e = 0; e < 3; e++)
    for (int a = 0; a < 6; a++) {
      hearth_rigid T;
      look_at(a * M_PI / 3 + e * 0.5, els[e], 0.35, &T);
      hearth_image img;
      render_sphere(&cam, &T, &img);
      CHECK_OK(hearth_tsdf_integrate(&vol, &img, &cam, &T, NULL, &err), &err);
      hearth_image_free(&img);
    }
  CHECK_OK(hearth_tsdf_extract(&vol, m, &err), &err);
  hearth_tsdf_free(&vol);
}

static void test_sphere(void) {
  hearth_err err = {0};
  hearth_mesh m;
  fuse_sphere(&m, 0.002);
  CHECK(m.n_triangles > 1000);
  CHECK_OK(hearth_mesh_keep_largest(&m, &err), &err);
  CHECK_OK(hearth_mesh_validate(&m, "sphere", &err), &err);
  size_t nb, nn;
  hearth_mesh_edge_stats(&m, &nb, &nn);
  CHECK_MSG(nb == 0 && nn == 0, "%zu boundary, %zu non-manifold edges", nb, nn);
  double to, from;
  sphere_stats(&m, &to, &from);
  printf("sphere: %zu triangles, RMS mesh->sphere %.3f mm, sphere->mesh %.3f mm\n", m.n_triangles,
         to * 1e3, from * 1e3);
  CHECK_MSG(to < 0.6e-3 && from < 0.6e-3, "RMS %g %g", to, from);
  /* outward normals: the signed volume is positive and near 4/3 pi R^3 */
  double vol = 0;
  for (size_t t = 0; t < m.n_triangles; t++) {
    const float *a = m.positions + 3 * (size_t)m.indices[3 * t];
    const float *b = m.positions + 3 * (size_t)m.indices[3 * t + 1];
    const float *c = m.positions + 3 * (size_t)m.indices[3 * t + 2];
    vol += (a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) -
            a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
            a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0])) /
           6.0;
  }
  double want = 4.0 / 3.0 * M_PI * SPHERE_R * SPHERE_R * SPHERE_R;
  CHECK_MSG(fabs(vol - want) < 0.03 * want, "volume %g, sphere %g", vol, want);

  /* simplification to a target count with bounded error, still closed */
  hearth_mesh s;
  CHECK_OK(hearth_mesh_copy(&m, &s, &err), &err);
  CHECK_OK(hearth_mesh_simplify(&s, 2000, &err), &err);
  CHECK_MSG(s.n_triangles <= 2000 && s.n_triangles >= 1900, "%zu triangles", s.n_triangles);
  hearth_mesh_edge_stats(&s, &nb, &nn);
  CHECK_MSG(nb == 0 && nn == 0, "simplified: %zu boundary, %zu non-manifold", nb, nn);
  double sto, sfrom;
  sphere_stats(&s, &sto, &sfrom);
  printf("simplified to %zu: RMS %.3f / %.3f mm\n", s.n_triangles, sto * 1e3, sfrom * 1e3);
  CHECK_MSG(sto < 0.8e-3 && sfrom < 0.8e-3, "RMS %g %g", sto, sfrom);
  hearth_mesh_free(&s);

  /* cut a cap off (triangles with a vertex above z = 0.045) and close it */
  CHECK_OK(hearth_mesh_copy(&m, &s, &err), &err);
  size_t w = 0;
  for (size_t t = 0; t < s.n_triangles; t++) {
    int cut = 0;
    for (int c = 0; c < 3; c++) cut |= s.positions[3 * (size_t)s.indices[3 * t + c] + 2] > 0.045f;
    if (cut) continue;
    memmove(s.indices + 3 * w++, s.indices + 3 * t, 3 * sizeof *s.indices);
  }
  s.n_triangles = w;
  hearth_mesh_edge_stats(&s, &nb, &nn);
  CHECK(nb > 20);
  size_t filled = 0, loops = 0, loop_edges = 0;
  CHECK_OK(hearth_mesh_open_loops(&s, &loops, &loop_edges, &err), &err);
  CHECK_MSG(loops == 1 && loop_edges == nb, "cut cap: %zu loops of %zu edges (%zu boundary)", loops,
            loop_edges, nb);
  CHECK_OK(hearth_mesh_fill_holes(&s, 10, &filled, &err), &err);
  CHECK(filled == 0); /* the loop is longer than 10 edges */
  CHECK_OK(hearth_mesh_fill_holes(&s, 1000, &filled, &err), &err);
  CHECK(filled == 1);
  hearth_mesh_edge_stats(&s, &nb, &nn);
  CHECK_MSG(nb == 0 && nn == 0, "filled: %zu boundary, %zu non-manifold", nb, nn);
  CHECK_OK(hearth_mesh_open_loops(&s, &loops, &loop_edges, &err), &err);
  CHECK(loops == 0 && loop_edges == 0);
  CHECK_OK(hearth_mesh_validate(&s, "filled", &err), &err);
  hearth_mesh_free(&s);
  hearth_mesh_free(&m);
}

static void test_errors(void) {
  hearth_err err = {0};
  hearth_tsdf vol;
  double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  CHECK(hearth_tsdf_init(&vol, lo, hi, 0, 1, &err) == HEARTH_E_ARG);
  CHECK(hearth_tsdf_init(&vol, lo, hi, 1e-4, 1e-3, &err) == HEARTH_E_LIMIT);
  hearth_mesh m;
  CHECK(hearth_recon_tsdf("/nonexistent", "cup_01", NULL, 0, NULL, &m, &err) == HEARTH_E_IO);
}

/* Reconstruct instance of release root and compare with its true mesh. */
static int run_release(const char *root, const char *instance, double voxel, size_t target,
                       double trunc, double *rms_a, double *rms_b, double *rms_vis) {
  hearth_err err = {0};
  hearth_recon_tsdf_opts o;
  hearth_recon_tsdf_opts_default(&o);
  o.voxel_m = voxel;
  o.target_triangles = target;
  o.trunc_m = trunc;
  hearth_mesh m, gt;
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  hearth_status s = hearth_recon_tsdf(root, instance, NULL, 0, &o, &m, &err);
  clock_gettime(CLOCK_MONOTONIC, &t1);
  CHECK_OK(s, &err);
  if (s) return -1;
  char path[1200];
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/mesh.glb", root, instance);
  CHECK_OK(hearth_glb_read(path, NULL, &gt, &err), &err);
  double mx_a, mx_b;
  const char *dump = getenv("RECON_TSDF_DUMP");
  if (dump) CHECK_OK(hearth_glb_write(dump, &m, &err), &err);
  mesh_to_mesh(&m, &gt, rms_a, &mx_a);
  mesh_to_mesh(&gt, &m, rms_b, &mx_b);
  /* true->recon over the true vertices some depth view sees */
  double mx_v = 0;
  uint8_t *vis = malloc(gt.n_vertices + 1);
  long nvis = vis ? true_visible_vertices(root, instance, &gt, vis) : -1;
  CHECK_MSG(nvis > 0, "%s: no true vertex visible", instance);
  if (nvis > 0) mesh_to_mesh_sel(&gt, vis, &m, rms_vis, &mx_v);
  free(vis);
  size_t nb, nn;
  hearth_mesh_edge_stats(&m, &nb, &nn);
  CHECK_MSG(nb == 0 && nn == 0, "%s: %zu boundary, %zu non-manifold edges", instance, nb, nn);
  printf(
      "%s: voxel %.1f mm, %zu triangles (%zu boundary, %zu non-manifold edges), %.2f s; "
      "RMS recon->true %.3f mm (max %.2f), true->recon %.3f mm (max %.2f), visible "
      "true->recon %.3f mm (max %.2f, %ld of %zu true vertices)\n",
      instance, voxel * 1e3, m.n_triangles, nb, nn,
      (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec), *rms_a * 1e3, mx_a * 1e3,
      *rms_b * 1e3, mx_b * 1e3, *rms_vis * 1e3, mx_v * 1e3, nvis, gt.n_vertices);
  hearth_mesh_free(&m);
  hearth_mesh_free(&gt);
  return 0;
}

/* The frame of the turntable: z along the axis, 0 at the turntable top.
 * The axis is the normal of the ring of camera centres (cameras above the
 * object), the top the lowest point of the true mesh along it. */
static void table_frame(const hearth_poses *p, const hearth_mesh *gt, hearth_rigid *T) {
  double m[3] = {0, 0, 0}, up[3] = {0, 0, 0}, g[3] = {0, 0, 0};
  for (size_t i = 0; i < p->n; i++)
    for (int a = 0; a < 3; a++) m[a] += p->views[i].T_world_from_cam.t[a] / (double)p->n;
  for (size_t i = 0; i < p->n; i++) {
    const double *c0 = p->views[i].T_world_from_cam.t,
                 *c1 = p->views[(i + 1) % p->n].T_world_from_cam.t;
    double a[3] = {c0[0] - m[0], c0[1] - m[1], c0[2] - m[2]};
    double b[3] = {c1[0] - m[0], c1[1] - m[1], c1[2] - m[2]};
    up[0] += a[1] * b[2] - a[2] * b[1];
    up[1] += a[2] * b[0] - a[0] * b[2];
    up[2] += a[0] * b[1] - a[1] * b[0];
  }
  for (size_t v = 0; v < gt->n_vertices; v++)
    for (int a = 0; a < 3; a++) g[a] += gt->positions[3 * v + a] / (double)gt->n_vertices;
  double n = sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
  double side = (m[0] - g[0]) * up[0] + (m[1] - g[1]) * up[1] + (m[2] - g[2]) * up[2];
  for (int a = 0; a < 3; a++) up[a] /= side < 0 ? -n : n;
  double lo = DBL_MAX;
  for (size_t v = 0; v < gt->n_vertices; v++) {
    double h = up[0] * gt->positions[3 * v] + up[1] * gt->positions[3 * v + 1] +
               up[2] * gt->positions[3 * v + 2];
    lo = h < lo ? h : lo;
  }
  /* rows e1, e2, up: e1 any unit vector across the axis */
  double e1[3] = {up[1], -up[0], 0};
  if (fabs(up[2]) > 0.9) e1[0] = 1, e1[1] = 0, e1[2] = -up[0] / up[2];
  double l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  for (int a = 0; a < 3; a++) e1[a] /= l1;
  double e2[3] = {up[1] * e1[2] - up[2] * e1[1], up[2] * e1[0] - up[0] * e1[2],
                  up[0] * e1[1] - up[1] * e1[0]};
  for (int a = 0; a < 3; a++) {
    T->R[a] = e1[a];
    T->R[3 + a] = e2[a];
    T->R[6 + a] = up[a];
  }
  T->t[0] = T->t[1] = 0;
  T->t[2] = -lo;
}

/* Openings no depth view reached stay open: the cup's inside below what
 * the views saw is left open (no patch made up across it, which lay up to
 * 20 mm from the true surface), the base it stands on is closed. */
static void test_openings(const char *root) {
  hearth_err err = {0};
  char path[1400];
  hearth_poses p = {0};
  hearth_mesh gt = {0}, m[2] = {{0}};
  snprintf(path, sizeof path, "%s/ground_truth/instances/cup_01/poses_rgb.json", root);
  CHECK_OK(hearth_poses_read(path, &p, &err), &err);
  snprintf(path, sizeof path, "%s/ground_truth/instances/cup_01/mesh.glb", root);
  CHECK_OK(hearth_glb_read(path, NULL, &gt, &err), &err);
  if (!p.n || !gt.n_vertices) goto done;
  hearth_rigid T;
  table_frame(&p, &gt, &T);
  for (size_t i = 0; i < p.n; i++) {
    hearth_rigid c = p.views[i].T_world_from_cam;
    hearth_rigid_compose(&T, &c, &p.views[i].T_world_from_cam);
  }
  for (size_t v = 0; v < gt.n_vertices; v++) {
    double x[3] = {gt.positions[3 * v], gt.positions[3 * v + 1], gt.positions[3 * v + 2]}, y[3];
    hearth_rigid_apply(&T, x, y);
    for (int a = 0; a < 3; a++) gt.positions[3 * v + a] = (float)y[a];
  }
  snprintf(path, sizeof path, "%s/table_poses.json", root);
  CHECK_OK(hearth_poses_write(path, &p, &err), &err);
  double rms[2], mx[2];
  for (int k = 0; k < 2; k++) {
    hearth_recon_tsdf_opts o;
    hearth_recon_tsdf_opts_default(&o);
    o.voxel_m = 0.003;
    o.poses = "table_poses.json";
    /* 2.5 voxels, as HEARTH_RECON_HOLE_SUPPORT_M at recon's 2 mm */
    o.hole_support_m = k ? 2.5 * o.voxel_m : 0;
    CHECK_OK(hearth_recon_tsdf(root, "cup_01", NULL, 0, &o, &m[k], &err), &err);
    mesh_to_mesh(&m[k], &gt, &rms[k], &mx[k]);
  }
  /* the boundary left: none at the base (within 3 mm of the top) */
  size_t nb, nn, low = 0;
  hearth_mesh_edge_stats(&m[1], &nb, &nn);
  for (size_t t = 0; t < m[1].n_triangles; t++)
    for (int c = 0; c < 3; c++) {
      uint32_t a = m[1].indices[3 * t + c], b = m[1].indices[3 * t + (c + 1) % 3];
      int twin = 0;
      for (size_t u = 0; u < m[1].n_triangles && !twin; u++)
        for (int d = 0; d < 3 && !twin; d++)
          twin = m[1].indices[3 * u + d] == b && m[1].indices[3 * u + (d + 1) % 3] == a;
      if (!twin && m[1].positions[3 * (size_t)a + 2] < 0.003f) low++;
    }
  printf(
      "openings: every loop closed: max recon->true %.2f mm (RMS %.3f); support rule: max "
      "%.2f mm (RMS %.3f), %zu boundary edges, %zu near the base\n",
      mx[0] * 1e3, rms[0] * 1e3, mx[1] * 1e3, rms[1] * 1e3, nb, low);
  CHECK_MSG(nb > 0 && nn == 0, "%zu boundary, %zu non-manifold edges", nb, nn);
  CHECK_MSG(low == 0, "%zu boundary edges at the base", low);
  /* what recon/report.json counts: the openings left, all the boundary */
  size_t loops[2] = {0, 0}, edges[2] = {0, 0};
  for (int k = 0; k < 2; k++)
    CHECK_OK(hearth_mesh_open_loops(&m[k], &loops[k], &edges[k], &err), &err);
  printf("openings: %zu loops of %zu edges left open (every loop closed: %zu)\n", loops[1],
         edges[1], loops[0]);
  CHECK_MSG(loops[0] == 0 && loops[1] >= 1 && edges[1] == nb, "open loops %zu / %zu, %zu edges",
            loops[0], loops[1], edges[1]);
  CHECK_MSG(mx[1] < 5e-3 && mx[0] > 2 * mx[1], "max recon->true %g (every loop closed %g)", mx[1],
            mx[0]);
done:
  hearth_mesh_free(&m[0]);
  hearth_mesh_free(&m[1]);
  hearth_mesh_free(&gt);
  hearth_poses_free(&p);
}

static void test_release(void) {
  const char *dir = test_tmpdir("recon_tsdf");
  char root[1100], cmd[1400];
  snprintf(root, sizeof root, "%s/rel", dir);
  snprintf(cmd, sizeof cmd,
           "%s synth --out '%s' --categories cup --states neutral --views 10 --no-calibration "
           "--draft-rgb --texture 256 --map-res 64 --quiet",
           HEARTH_EXE, root);
  CHECK(system(cmd) == 0);
  double a, b, bv;
  if (run_release(root, "cup_01", 0.003, 20000, 0, &a, &b, &bv) == 0) {
    /* 10 views leave the cup's inside partly unseen: the true inner
     * walls lie up to a few mm from the reconstruction */
    CHECK_MSG(a < 1.5e-3 && b < 3.5e-3, "RMS %g %g", a, b);
    /* the true surface some depth view sees is reconstructed: within the
     * issue's 1.5 mm even at 3 mm voxels (0.8 mm measured) */
    CHECK_MSG(bv < 1.5e-3 && bv < b, "visible true->recon RMS %g (all %g)", bv, b);
  }
  test_openings(root);
}

int main(int argc, char **argv) {
  if (argc >= 3) {
    double a, b, bv;
    double voxel = argc >= 4 ? atof(argv[3]) : 0.002;
    size_t target = argc >= 5 ? (size_t)atol(argv[4]) : 20000;
    double trunc = argc >= 6 ? atof(argv[5]) : 0;
    return run_release(argv[1], argv[2], voxel, target, trunc, &a, &b, &bv) ? 1 : g_test_failures;
  }
  test_errors();
  test_sphere();
  test_release();
  return g_test_failures;
}
