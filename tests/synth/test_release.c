/* The virtual rig's release: every file of the layout contract, the ground
 * truth's internal consistency (recon x scale == truth, thermal pose ==
 * rgb pose * inverse(rig)), the thermal images against the temperature field
 * seen through an independent pixel-centre ray, determinism across runs and
 * thread counts, and refusal to overwrite. Small releases only. */
#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "hearth/image.h"
#include "hearth/mesh.h"
#include "hearth/npy.h"
#include "hearth/dataset.h"
#include "hearth/synth.h"
#include "hearth/thermal.h"
#include "synth/synth_rig.h"
#include "test_util.h"

static void small_opts(hearth_synth_opts *o, const char *root, int threads) {
  hearth_synth_opts_default(o);
  o->ideal = 1; /* closed-form: the clean rig */
  o->seed = 7;
  o->out_root = root;
  o->n_views = 4;
  o->triangles = 2000;
  o->texture_size = 256;
  o->map_resolution = 128;
  o->n_thermal_frames = 5; /* frame f004 is one of the partial frames */
  o->n_stereo_pairs = 1;
  o->threads = threads;
  o->quiet = 1;
  o->rgb_full_size = 0; /* draft colour keeps the test fast; test_synth_cli covers full size */
}

static int exists(const char *root, const char *rel) {
  char p[4096];
  snprintf(p, sizeof p, "%s/%s", root, rel);
  struct stat sb;
  return stat(p, &sb) == 0 && sb.st_size > 0;
}

static int same_bytes(const char *a_root, const char *b_root, const char *rel) {
  char pa[4096], pb[4096];
  snprintf(pa, sizeof pa, "%s/%s", a_root, rel);
  snprintf(pb, sizeof pb, "%s/%s", b_root, rel);
  uint8_t *a = NULL, *b = NULL;
  size_t na = 0, nb = 0;
  hearth_err err;
  int ok = hearth_read_file(pa, 1u << 30, &a, &na, &err) == HEARTH_OK &&
           hearth_read_file(pb, 1u << 30, &b, &nb, &err) == HEARTH_OK && na == nb &&
           memcmp(a, b, na) == 0;
  free(a);
  free(b);
  return ok;
}

static void test_lens(void) {
  /* the rig's inversion reproduces pixels through its own forward model,
   * and the forward model is the documented Brown-Conrady expression */
  hearth_rig rig;
  synth_rig_draw(3, &rig);
  const hearth_camera *c = &rig.thermal;
  double worst = 0;
  for (double v = 0; v < 192; v += 7.5)
    for (double u = 0; u < 256; u += 7.5) {
      double d[3], uv[2];
      synth_lens_ray(c, u, v, d);
      CHECK(synth_lens_project(c, d, uv));
      worst = fmax(worst, hypot(uv[0] - u, uv[1] - v));
    }
  CHECK_MSG(worst < 1e-8, "round trip error %g px", worst);
  double x = 0.31, y = -0.22, r2 = x * x + y * y, k1 = c->dist[0], k2 = c->dist[1], p1 = c->dist[2],
         p2 = c->dist[3], k3 = c->dist[4], xd, yd;
  synth_lens_distort(c->dist, x, y, &xd, &yd);
  double rad = 1 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2;
  CHECK_NEAR(xd, x * rad + 2 * p1 * x * y + p2 * (r2 + 2 * x * x), 1e-15);
  CHECK_NEAR(yd, y * rad + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y, 1e-15);
  /* realistic ranges: ~50 x 37 degrees, a few cm baseline */
  double hx = atan(128.0 / c->fx) * 2 * 180 / M_PI;
  CHECK(c->dist[0] <= -0.15 && c->dist[0] >= -0.35);
  {
    double l[3], r[3];
    synth_lens_ray(c, -0.5, c->cy, l);
    synth_lens_ray(c, 255.5, c->cy, r);
    double fov = acos(hearth_dot3(l, r)) * 180 / M_PI;
    CHECK_MSG(fov > 46 && fov < 54, "thermal hfov %g (pinhole %g)", fov, hx);
  }
  double b = hearth_norm3(rig.T_thermal_from_rgb.t);
  CHECK(b > 0.02 && b < 0.1);
  CHECK(rig.rgb.fx > 1090 && rig.rgb.fx < 1170 && rig.rgb.width == 1920);
}

/* thermal CSV vs the field at the surface point under the pixel centre */
static void check_thermal_vs_field(const char *root, const hearth_synth_opts *o,
                                   const hearth_rig *rig) {
  synth_instance *inst = calloc(1, sizeof *inst);
  hearth_err err = {0};
  CHECK_OK(synth_instance_make(o, rig, "cup", 0, NULL, inst, &err), &err);
  synth_scene scene;
  CHECK_OK(synth_scene_init(&scene, &inst->obj, &inst->T_world_from_obj, inst->ambient_c, &err),
           &err);
  hearth_rigid T_rgb_from_th;
  hearth_rigid_inverse(&rig->T_thermal_from_rgb, &T_rgb_from_th);
  size_t n_obj = 0, n_bg = 0, bad_obj = 0, bad_bg = 0;
  double worst = 0;
  for (size_t s = 0; s < inst->n_states; s++)
    for (size_t v = 0; v < inst->n_views; v++) {
      char p[4096];
      snprintf(p, sizeof p, "%s/instances/%s/raw/%s/thermal/%s.csv", root, inst->id,
               inst->states[s], inst->views[s][v].name);
      hearth_image img = {0};
      CHECK_OK(hearth_thermal_read_csv(p, NULL, &img, &err), &err);
      if (!img.data) continue;
      const float *T = img.data;
      hearth_rigid Tw;
      hearth_rigid_compose(&inst->views[s][v].T_world_from_rgb, &T_rgb_from_th, &Tw);
      for (int y = 2; y < 190; y += 3)
        for (int x = 2; x < 254; x += 3) {
          /* the 3x3 neighbourhood, probed every half pixel (7 x 7 rays) */
          double vals[49], vmin = 1e9, vmax = -1e9;
          int hits = 0, misses = 0, part = -1, same_part = 1;
          for (int k = 0; k < 49; k++) {
            double dc[3], dw[3];
            synth_lens_ray(&rig->thermal, x + 0.5 * (k % 7 - 3), y + 0.5 * (k / 7 - 3), dc);
            hearth_rigid_rotate(&Tw, dc, dw);
            hearth_ray_hit h;
            if (hearth_raycast(scene.rc, Tw.t, dw, 0.0, 10.0, &h)) {
              const uint32_t *id = inst->obj.mesh.indices + 3 * (size_t)h.prim;
              const float *P = inst->obj.mesh.positions;
              double q[3], b0 = 1.0 - h.b1 - h.b2;
              for (int j = 0; j < 3; j++)
                q[j] = b0 * P[3 * id[0] + j] + h.b1 * P[3 * id[1] + j] + h.b2 * P[3 * id[2] + j];
              vals[k] = synth_field_eval(&inst->fields[s], &inst->obj, h.prim, q);
              vmin = fmin(vmin, vals[k]);
              vmax = fmax(vmax, vals[k]);
              int pt = inst->obj.part_of_tri ? inst->obj.part_of_tri[h.prim] : 0;
              if (part < 0) part = pt;
              if (pt != part) same_part = 0;
              hits++;
            } else {
              misses++;
            }
          }
          double meas = T[(size_t)y * 256 + (size_t)x];
          if (hits == 49 && same_part && vmax - vmin < 0.25) {
            n_obj++;
            double e = fabs(meas - vals[24]);
            worst = fmax(worst, e);
            if (e > 0.3) bad_obj++;
          } else if (misses == 49) {
            n_bg++;
            if (fabs(meas - inst->ambient_c) > 1.0) bad_bg++;
          }
        }
      hearth_image_free(&img);
    }
  CHECK_MSG(n_obj > 200, "only %zu smooth object pixels", n_obj);
  CHECK_MSG(n_bg > 200, "only %zu background pixels", n_bg);
  CHECK_MSG(bad_obj == 0, "%zu of %zu object pixels off the field by > 0.3 (worst %g)", bad_obj,
            n_obj, worst);
  CHECK_MSG(bad_bg == 0, "%zu of %zu background pixels far from ambient", bad_bg, n_bg);
  synth_scene_free(&scene);
  synth_instance_free(inst);
  free(inst);
}

static void check_release(const char *root, const hearth_synth_opts *o) {
  hearth_err err = {0};
  char p[4096];
  /* release and instance documents */
  hearth_release_doc rel;
  memset(&rel, 0, sizeof rel);
  snprintf(p, sizeof p, "%s/release.json", root);
  CHECK_OK(hearth_release_read(p, &rel, &err), &err);
  CHECK(rel.n_instances == 1 && rel.instances && !strcmp(rel.instances[0], "cup_01"));
  hearth_release_free(&rel);
  hearth_instance_doc doc;
  snprintf(p, sizeof p, "%s/instances/cup_01/instance.json", root);
  CHECK_OK(hearth_instance_read(p, &doc, &err), &err);
  CHECK(doc.n_states == 2 && !strcmp(doc.states[0], "neutral") && !strcmp(doc.category, "cup"));

  /* rig: ground truth equals the one drawn from the seed; factory file */
  hearth_rig rig, drawn;
  snprintf(p, sizeof p, "%s/ground_truth/rig.json", root);
  CHECK_OK(hearth_rig_read(p, &rig, &err), &err);
  synth_rig_draw(o->seed, &drawn);
  CHECK_NEAR(rig.thermal.fx, drawn.thermal.fx, 1e-9);
  CHECK_NEAR(rig.thermal.dist[0], drawn.thermal.dist[0], 1e-9);
  CHECK_NEAR(rig.T_thermal_from_rgb.t[1], drawn.T_thermal_from_rgb.t[1], 1e-9);
  hearth_factory_calib fac;
  snprintf(p, sizeof p, "%s/calibration/factory.json", root);
  CHECK_OK(hearth_factory_read(p, &fac, &err), &err);
  CHECK_NEAR(fac.rgb.fx, rig.rgb.fx, 1e-9);
  CHECK_NEAR(fac.depth.cy, rig.depth.cy, 1e-9);
  CHECK_NEAR(fac.T_depth_from_rgb.t[0], rig.T_depth_from_rgb.t[0], 1e-9);

  /* raw captures */
  for (size_t s = 0; s < doc.n_states; s++) {
    hearth_manifest man = {0};
    snprintf(p, sizeof p, "%s/instances/cup_01/raw/%s/manifest.json", root, doc.states[s]);
    CHECK_OK(hearth_manifest_read(p, &man, &err), &err);
    CHECK(man.n_views == 4);
    const char *names[4] = {"v00", "v07", "v15", "v22"};
    for (size_t v = 0; v < man.n_views && v < 4; v++) {
      hearth_view_files *vf = &man.views[v];
      CHECK(!strcmp(vf->view, names[v]));
      CHECK(vf->elevation_index * 10 + vf->azimuth_index == atoi(names[v] + 1));
      char dir[4096];
      snprintf(dir, sizeof dir, "%s/instances/cup_01/raw/%s", root, doc.states[s]);
      hearth_image img = {0};
      snprintf(p, sizeof p, "%s/%s", dir, vf->thermal);
      CHECK_OK(hearth_thermal_read_csv(p, NULL, &img, &err), &err);
      CHECK(img.width == 256 && img.height == 192);
      hearth_image_free(&img);
      snprintf(p, sizeof p, "%s/%s", dir, vf->depth);
      CHECK_OK(hearth_png_read(p, &img, &err), &err);
      CHECK(img.width == 640 && img.height == 576 && img.type == HEARTH_PIX_U16 &&
            img.channels == 1);
      if (img.data) {
        /* valid depths are plausible distances; some pixels are holes */
        size_t zeros = 0, n = img.width * img.height;
        const uint16_t *d = img.data;
        for (size_t i = 0; i < n; i++) zeros += d[i] == 0;
        CHECK_MSG(zeros > 0 && zeros < n * 6 / 10, "%zu of %zu depth pixels invalid", zeros, n);
      }
      hearth_image_free(&img);
      snprintf(p, sizeof p, "%s/%s", dir, vf->rgb);
      CHECK_OK(hearth_jpeg_read(p, &img, &err), &err);
      CHECK(img.width == 1920 && img.height == 1080 && img.channels == 3);
      hearth_image_free(&img);
      snprintf(p, sizeof p, "%s/%s", dir, vf->cutout);
      CHECK_OK(hearth_png_read(p, &img, &err), &err);
      CHECK(img.width == 1920 && img.height == 1080 && img.channels == 1);
      if (img.data) {
        size_t on = 0, other = 0, n = img.width * img.height;
        const uint8_t *m = img.data;
        for (size_t i = 0; i < n; i++) {
          on += m[i] == 255;
          other += m[i] != 255 && m[i] != 0;
        }
        CHECK(on > 5000 && on < n / 2 && other == 0);
      }
      hearth_image_free(&img);
      hearth_depth_intrinsics di;
      snprintf(p, sizeof p, "%s/%s", dir, vf->depth_intrinsics);
      CHECK_OK(hearth_depth_intrinsics_read(p, &di, &err), &err);
      CHECK_NEAR(di.depth.fx, rig.depth.fx, 1e-9);
    }
    hearth_manifest_free(&man);
    snprintf(p, sizeof p, "ground_truth/instances/cup_01/%s/temperature_true.npy", doc.states[s]);
    CHECK(exists(root, p));
    hearth_npy a = {0};
    char q[4096];
    snprintf(q, sizeof q, "%s/%s", root, p);
    CHECK_OK(hearth_npy_read(q, &a, &err), &err);
    CHECK(a.dtype == HEARTH_NPY_F32 && a.ndim == 2 && a.shape[0] == 128 && a.shape[1] == 128);
    if (a.data && a.ndim == 2) {
      size_t nan = 0, fin = 0;
      const float *t = a.data;
      for (size_t i = 0; i < 128 * 128; i++) {
        if (isnan(t[i])) nan++;
        else if (t[i] > 0 && t[i] < 100) fin++;
      }
      CHECK(nan > 0 && fin > 1000 && nan + fin == 128 * 128);
    }
    hearth_npy_free(&a);
  }
  CHECK(exists(root, "instances/cup_01/recon/rgb_texture.png"));

  /* calibration captures and their truth */
  CHECK(exists(root, "calibration/captures/thermal/f000.csv"));
  CHECK(exists(root, "calibration/captures/thermal/f004.csv"));
  CHECK(exists(root, "calibration/captures/stereo/p000_rgb.jpg"));
  CHECK(exists(root, "calibration/captures/stereo/p000_thermal.csv"));
  hearth_detections dets = {0};
  snprintf(p, sizeof p, "%s/ground_truth/calibration/detections.json", root);
  CHECK_OK(hearth_detections_read(p, &dets, &err), &err);
  CHECK(dets.n == 7);
  for (size_t i = 0; i < dets.n; i++) {
    const hearth_detection *d = &dets.frames[i];
    int partial = !strcmp(d->frame, "f004");
    CHECK_MSG(d->found == !partial, "%s/%s found=%d", d->frame, d->camera, d->found);
    if (!d->found) CHECK(strstr(d->reason, "holes visible") != NULL);
    const hearth_camera *c = !strcmp(d->camera, "rgb") ? &rig.rgb : &rig.thermal;
    if (d->found) {
      /* centres inside the image, ordered row by row (left to right, tilts
       * stay well below 45 degrees) */
      for (int k = 0; k < HEARTH_PLATE_HOLES; k++)
        CHECK(d->centres[k][0] > 0 && d->centres[k][0] < c->width && d->centres[k][1] > 0 &&
              d->centres[k][1] < c->height);
      CHECK(d->centres[1][0] > d->centres[0][0] && d->centres[83][1] > d->centres[0][1]);
    }
  }
  hearth_detections_free(&dets);

  /* recon mesh x true scale == ground-truth mesh; same UVs */
  hearth_scale_doc sd;
  snprintf(p, sizeof p, "%s/ground_truth/instances/cup_01/scale.json", root);
  CHECK_OK(hearth_scale_doc_read(p, &sd, &err), &err);
  CHECK(sd.scale >= 0.3 && sd.scale <= 3.0);
  hearth_glb_read_opts ro = {1, 1, 0};
  hearth_mesh mr = {0}, mg = {0};
  snprintf(p, sizeof p, "%s/instances/cup_01/recon/mesh.glb", root);
  CHECK_OK(hearth_glb_read(p, &ro, &mr, &err), &err);
  snprintf(p, sizeof p, "%s/ground_truth/instances/cup_01/mesh.glb", root);
  CHECK_OK(hearth_glb_read(p, &ro, &mg, &err), &err);
  CHECK(mr.n_vertices == mg.n_vertices && mr.n_triangles == mg.n_triangles && mr.n_vertices > 0);
  CHECK(mr.texture.data != NULL && mr.texture.width == 256);
  if (mr.n_vertices == mg.n_vertices && mr.uvs && mg.uvs) {
    double worst = 0, worst_uv = 0;
    for (size_t i = 0; i < 3 * mr.n_vertices; i++)
      worst = fmax(worst, fabs(mr.positions[i] * sd.scale - mg.positions[i]));
    for (size_t i = 0; i < 2 * mr.n_vertices; i++)
      worst_uv = fmax(worst_uv, fabs(mr.uvs[i] - mg.uvs[i]));
    CHECK_MSG(worst < 1e-5, "recon x scale vs truth: %g m", worst);
    CHECK(worst_uv == 0);
    /* metric size is the object's: a cup is 5-20 cm */
    double lo[3], hi[3];
    hearth_mesh_bounds(&mg, lo, hi);
    double ext = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    CHECK_MSG(ext > 0.05 && ext < 0.25, "metric extent %g", ext);
  }
  hearth_mesh_free(&mr);
  hearth_mesh_free(&mg);

  /* poses: thermal truth = rgb truth * inverse(T_thermal_from_rgb); recon
   * poses = truth / scale up to small noise */
  hearth_poses pr = {0}, pt = {0}, pc = {0};
  snprintf(p, sizeof p, "%s/ground_truth/instances/cup_01/poses_rgb.json", root);
  CHECK_OK(hearth_poses_read(p, &pr, &err), &err);
  snprintf(p, sizeof p, "%s/ground_truth/instances/cup_01/poses_thermal.json", root);
  CHECK_OK(hearth_poses_read(p, &pt, &err), &err);
  snprintf(p, sizeof p, "%s/instances/cup_01/recon/poses_rgb.json", root);
  CHECK_OK(hearth_poses_read(p, &pc, &err), &err);
  CHECK(pr.n == 8 && pt.n == 8 && pc.n == 8);
  hearth_rigid inv;
  hearth_rigid_inverse(&rig.T_thermal_from_rgb, &inv);
  for (size_t i = 0; i < pr.n; i++) {
    const hearth_view_pose *a = &pr.views[i];
    const hearth_view_pose *b = hearth_poses_find(&pt, a->state, a->view);
    const hearth_view_pose *c = hearth_poses_find(&pc, a->state, a->view);
    CHECK(b && c);
    if (!b || !c) continue;
    hearth_rigid e;
    hearth_rigid_compose(&a->T_world_from_cam, &inv, &e);
    for (int k = 0; k < 9; k++) CHECK_NEAR(e.R[k], b->T_world_from_cam.R[k], 1e-9);
    for (int k = 0; k < 3; k++) CHECK_NEAR(e.t[k], b->T_world_from_cam.t[k], 1e-9);
    double ang = hearth_rotation_angle_between(a->T_world_from_cam.R, c->T_world_from_cam.R);
    CHECK_MSG(ang * 180 / M_PI < 0.8, "recon rotation noise %g deg", ang * 180 / M_PI);
    double dt = 0;
    for (int k = 0; k < 3; k++)
      dt += pow(c->T_world_from_cam.t[k] * sd.scale - a->T_world_from_cam.t[k], 2);
    CHECK_MSG(sqrt(dt) < 0.003, "recon translation noise %g m", sqrt(dt));
  }
  hearth_poses_free(&pr);
  hearth_poses_free(&pt);
  hearth_poses_free(&pc);

  check_thermal_vs_field(root, o, &rig);
}

int main(void) {
  test_lens();
  const char *base = test_tmpdir("synth_release");
  char a[2048], b[2048], c[2048];
  snprintf(a, sizeof a, "%s/a", base);
  snprintf(b, sizeof b, "%s/b", base);
  snprintf(c, sizeof c, "%s/c", base);
  hearth_synth_opts o;
  hearth_err err = {0};

  small_opts(&o, a, 2);
  CHECK_OK(hearth_synth_release(&o, &err), &err);
  check_release(a, &o);

  /* same seed, one thread, into an existing empty directory: same bytes */
  CHECK(mkdir(b, 0777) == 0);
  small_opts(&o, b, 1);
  CHECK_OK(hearth_synth_release(&o, &err), &err);
  const char *files[] = {"instances/cup_01/raw/hot/thermal/v07.csv",
                         "instances/cup_01/raw/neutral/rgb/v15.jpg",
                         "instances/cup_01/raw/hot/depth/v22.png",
                         "instances/cup_01/raw/hot/cutout/v00.png",
                         "instances/cup_01/recon/poses_rgb.json",
                         "instances/cup_01/recon/mesh.glb",
                         "ground_truth/instances/cup_01/hot/temperature_true.npy",
                         "ground_truth/calibration/detections.json",
                         "calibration/captures/stereo/p000_rgb.jpg",
                         "calibration/captures/thermal/f002.csv"};
  for (size_t i = 0; i < sizeof files / sizeof files[0]; i++)
    CHECK_MSG(same_bytes(a, b, files[i]), "%s differs between runs", files[i]);

  /* a different seed gives a different capture */
  small_opts(&o, c, 2);
  o.seed = 8;
  o.calibration = 0;
  o.n_views = 1;
  CHECK_OK(hearth_synth_release(&o, &err), &err);
  CHECK(!same_bytes(a, c, "instances/cup_01/raw/hot/thermal/v00.csv"));
  CHECK(!exists(c, "calibration/captures/thermal/f000.csv"));

  /* refusal: a non-empty out_root is left alone and nothing is left beside it */
  small_opts(&o, a, 2);
  err.msg[0] = 0;
  hearth_status st = hearth_synth_release(&o, &err);
  CHECK(st != HEARTH_OK);
  CHECK(strstr(err.msg, a) != NULL);
  CHECK(exists(a, "release.json"));
  /* bad options are refused up front, naming the value */
  char d[2048];
  snprintf(d, sizeof d, "%s/d", base);
  small_opts(&o, d, 2);
  o.categories[0] = "no_such_thing";
  CHECK(hearth_synth_release(&o, &err) != HEARTH_OK);
  CHECK(strstr(err.msg, "no_such_thing") != NULL);
  CHECK(!hearth_path_exists(d));
  /* a failure mid-way (the mesh file is missing, found after the
   * calibration captures were written) removes the temporary tree */
  small_opts(&o, d, 2);
  o.n_thermal_frames = 1;
  o.n_stereo_pairs = 0;
  o.mesh_path = "/nonexistent/dir/object.glb";
  CHECK(hearth_synth_release(&o, &err) != HEARTH_OK);
  CHECK(strstr(err.msg, "object.glb") != NULL);
  CHECK(!hearth_path_exists(d));
  DIR *dir = opendir(base);
  struct dirent *e;
  int leftovers = 0;
  while (dir && (e = readdir(dir)))
    if (strstr(e->d_name, "tmp")) leftovers++;
  if (dir) closedir(dir);
  CHECK(leftovers == 0);
  TEST_MAIN_END();
}
