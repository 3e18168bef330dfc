/* Overlays of a closed, outward-facing mesh are cast through the ray fan
 * (front faces rasterised); those of the same mesh with every triangle
 * reversed (closed but facing inward: the fan would see the far side) are
 * traced by Embree, which culls no face. Both see the same surface, so the
 * outlines must agree but for a few sub-pixels where a ray grazes the
 * silhouette within float rounding: two casters, one answer. On a
 * virtual-rig cup and can with their true mesh, rig and thermal poses.
 * The test of closedness that picks the caster is checked first: the true
 * meshes pass, reversed or with a triangle gone they do not. */
#include "hearth/mesh.h"
#include "hearth/poses.h"
#include "hearth/synth.h"
#include "poses/poses_internal.h"
#include "test_util.h"

enum { NI = 2, NV = 6 };

/* every per-view overlay of the state, decoded */
static void read_overlays(const char *root, const char *inst, const char *state,
                          hearth_image *img) {
  hearth_err err = {0};
  for (int v = 0; v < NV; v++) {
    char path[1400];
    snprintf(path, sizeof path, "%s/instances/%s/derived/overlay/%s/v%02d.png", root, inst, state,
             5 * v); /* the views of 6 around the turntable: v00, v05, .. */
    CHECK_OK(hearth_png_read(path, &img[v], &err), &err);
  }
}

int main(void) {
  const char *dir = test_tmpdir("overlay_fan");
  char root[1200];
  snprintf(root, sizeof root, "%s/release", dir);
  hearth_synth_opts so;
  hearth_synth_opts_default(&so);
  so.out_root = root;
  so.seed = 5;
  so.n_categories = NI;
  so.categories[0] = "cup";
  so.categories[1] = "canned_drink";
  so.n_views = NV;
  so.triangles = 4000;
  so.texture_size = 64;
  so.map_resolution = 64;
  so.calibration = 0;
  so.quiet = 1;
  hearth_err err = {0};
  CHECK_OK(hearth_synth_release(&so, &err), &err);
  const char *inst[NI] = {"cup_01", "canned_drink_01"};
  char rig[1400], mesh[1400], flipped[1400], poses[1400];
  snprintf(rig, sizeof rig, "%s/ground_truth/rig.json", root);
  for (int i = 0; i < NI; i++) {
    snprintf(mesh, sizeof mesh, "%s/ground_truth/instances/%s/mesh.glb", root, inst[i]);
    snprintf(poses, sizeof poses, "%s/ground_truth/instances/%s/poses_thermal.json", root, inst[i]);
    snprintf(flipped, sizeof flipped, "%s/flipped_%s.glb", dir, inst[i]);
    hearth_mesh m = {0};
    hearth_glb_read_opts go = {0};
    CHECK_OK(hearth_glb_read(mesh, &go, &m, &err), &err);
    CHECK_MSG(rf_mesh_closed_outward(&m), "%s: the true mesh is closed", inst[i]);
    m.n_triangles--;
    CHECK_MSG(!rf_mesh_closed_outward(&m), "%s: a triangle short is open", inst[i]);
    m.n_triangles++;
    for (size_t t = 0; t < m.n_triangles; t++) {
      uint32_t k = m.indices[3 * t + 1];
      m.indices[3 * t + 1] = m.indices[3 * t + 2];
      m.indices[3 * t + 2] = k;
    }
    CHECK_MSG(!rf_mesh_closed_outward(&m), "%s: reversed, it faces inward", inst[i]);
    CHECK_OK(hearth_glb_write(flipped, &m, &err), &err);
    hearth_mesh_free(&m);
    hearth_image fan[NV] = {{0}}, traced[NV] = {{0}};
    hearth_overlay_job job;
    hearth_overlay_job_default(&job);
    job.root = root;
    job.instance = inst[i];
    job.state = "neutral";
    job.rig_path = rig;
    job.before_path = poses;
    job.after_path = poses;
    job.zoom = 2;
    job.threads = 2;
    job.mesh_path = mesh;
    CHECK_OK(hearth_overlay_run(&job, NULL, &err), &err);
    read_overlays(root, inst[i], "neutral", fan);
    job.mesh_path = flipped;
    CHECK_OK(hearth_overlay_run(&job, NULL, &err), &err);
    read_overlays(root, inst[i], "neutral", traced);
    size_t differ = 0, outline = 0;
    for (int v = 0; v < NV; v++) {
      CHECK(fan[v].width == traced[v].width && fan[v].height == traced[v].height);
      const uint8_t *a = fan[v].data, *b = traced[v].data;
      for (size_t p = 0; p < fan[v].width * fan[v].height; p++) {
        differ += memcmp(a + 3 * p, b + 3 * p, 3) != 0;
        outline += a[3 * p] == 255 && a[3 * p + 1] == 255 && a[3 * p + 2] == 255;
      }
      hearth_image_free(&fan[v]);
      hearth_image_free(&traced[v]);
    }
    /* the outlines are there, and the two casters draw the same ones */
    CHECK_MSG(outline > 300 * NV, "%s: %zu white sub-pixels", inst[i], outline);
    CHECK_MSG(differ <= 2 * NV, "%s: %zu sub-pixels differ (of %zu outline)", inst[i], differ,
              outline);
  }
  TEST_MAIN_END();
}
