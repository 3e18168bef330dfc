/* hearth build on a virtual-rig release without recon/ (synth --recon none):
 * the build reconstructs (a recon stage with its stamp, the colour texture
 * baked into recon/), and the mapped temperatures meet the truth through
 * surface correspondence. The truth is the rig's own: each texel's point on
 * hearth's mesh matched to the nearest point of the true mesh, whose UV
 * picks ground_truth's temperature. A correspondence through a wrong frame
 * (the true similarity turned 90 degrees about the mesh's up axis, or moved
 * 15 mm) fails the same bounds, so they test the matching. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/hearth.h"
#include "test_util.h"

static int cmp_d(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* median and p95 of |observed - apparent| (what a view along the normal
   reads: the truth a thermal camera can recover under the rig's object
   effects) over observed texels seen within 60 degrees, and their share of
   the observed texels */
static void figures(const char *root, const hearth_similarity *S, double *med, double *p95,
                    double *share) {
  char path[2048];
  hearth_err err = {0};
  hearth_npy mask = {0}, obs = {0};
  snprintf(path, sizeof path, "%s/instances/cup_01/derived/hot/mask.npy", root);
  CHECK_OK(hearth_npy_read(path, &mask, &err), &err);
  snprintf(path, sizeof path, "%s/instances/cup_01/derived/hot/temperature_observed.npy", root);
  CHECK_OK(hearth_npy_read(path, &obs, &err), &err);
  *med = *p95 = 99;
  *share = 0;
  hearth_truth_match tm = {0};
  size_t R = mask.ndim == 2 ? mask.shape[0] : 0;
  CHECK_OK(hearth_truth_match_state(root, "cup_01", "hot", R, S, &tm, &err), &err);
  CHECK(!tm.same_uvs && tm.t_apparent);
  const uint8_t *m = mask.data;
  const float *o = obs.data;
  double *d = calloc(R * R + 1, sizeof *d);
  size_t k = 0, n_obs = 0;
  for (size_t i = 0; tm.t_true && d && i < R * R; i++) {
    if (m[i] != 1 || !isfinite(o[i])) continue;
    n_obs++;
    if (tm.away[i] && isfinite(tm.t_apparent[i])) d[k++] = fabs((double)o[i] - tm.t_apparent[i]);
  }
  if (k) {
    qsort(d, k, sizeof *d, cmp_d);
    *med = d[k / 2];
    *p95 = d[(size_t)(0.95 * (double)(k - 1))];
    *share = (double)k / (double)n_obs;
  }
  if (!S) {
    /* the frame: hearth's recon is metric, so the similarity's scale is 1 */
    CHECK_MSG(fabs(tm.alignment.ref_from_est.s - 1.0) < 0.01, "scale %g",
              tm.alignment.ref_from_est.s);
  }
  free(d);
  hearth_truth_match_free(&tm);
  hearth_npy_free(&mask);
  hearth_npy_free(&obs);
}

int main(void) {
  const char *base = test_tmpdir("recon_truth");
  char root[1200], path[1400], cmd[4096];
  static char out[1 << 16];
  hearth_err err = {0};
  snprintf(root, sizeof root, "%s/rel", base);
  snprintf(cmd, sizeof cmd,
           "'%s' synth --out '%s' --categories cup --states hot --views 12 --no-calibration "
           "--texture 256 --map-res 96 --recon none --quiet && "
           "cp '%s/ground_truth/rig.json' '%s/calibration/rig.json'",
           HEARTH_EXE, root, root, root);
  CHECK(system(cmd) == 0);

  /* the build reconstructs: a recon stage, then the usual ones */
  snprintf(cmd, sizeof cmd,
           "'%s' build '%s' --resolution 96 --rgb-resolution 256 --fusion corrected --threads 2",
           HEARTH_EXE, root);
  int rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0 && strstr(out, "cup_01 recon: done"), "build: exit %d: %s", rc, out);
  static const char *const k_recon[] = {"poses_rgb.json",    "poses_rgb_cameras.json",
                                        "mesh_geometry.glb", "mesh.glb",
                                        "rgb_texture.png",   "report.json"};
  for (int i = 0; i < 6; i++) {
    snprintf(path, sizeof path, "%s/instances/cup_01/recon/%s", root, k_recon[i]);
    CHECK_MSG(hearth_path_exists(path), "%s missing", path);
  }
  /* recon/mesh.glb is the hand-over an outside tool gives: UVs and the
     colour texture embedded, the same image as recon/rgb_texture.png */
  {
    hearth_glb_read_opts go;
    hearth_glb_read_opts_default(&go);
    go.require_uvs = 1;
    go.load_texture = 1;
    hearth_mesh m = {0};
    hearth_image tex = {0};
    snprintf(path, sizeof path, "%s/instances/cup_01/recon/mesh.glb", root);
    CHECK_OK(hearth_glb_read(path, &go, &m, &err), &err);
    snprintf(path, sizeof path, "%s/instances/cup_01/recon/rgb_texture.png", root);
    CHECK_OK(hearth_png_read(path, &tex, &err), &err);
    CHECK(m.texture.data && tex.data && m.texture.width == 256 && tex.width == 256 &&
          m.texture.height == tex.height && m.texture.channels == tex.channels &&
          !memcmp(m.texture.data, tex.data, hearth_image_bytes(&tex)));
    /* the texture is the object's colours, not the bake's grey fill */
    size_t grey = 0, n = tex.width * tex.height;
    const uint8_t *px = tex.data;
    for (size_t i = 0; px && i < n; i++)
      grey += px[i * tex.channels] == 128 && px[i * tex.channels + 1] == 128;
    CHECK_MSG(grey < n * 3 / 4, "%zu of %zu texels grey", grey, n);
    hearth_mesh_free(&m);
    hearth_image_free(&tex);
  }
  /* a second build runs nothing, recon included */
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0 && strstr(out, " 0 stage(s) run"), "rebuild: %s", out);

  /* through correspondence: a hot cup at R 96 on hearth's own poses and
     mesh (the frame fits the truth to about 2 mm; nearest texel of the
     truth; lens blur at the cup's edges and rim) */
  double med, p95, share;
  figures(root, NULL, &med, &p95, &share);
  printf("correspondence: median %.3f C, p95 %.3f C, %.1f %% of observed texels\n", med, p95,
         100 * share);
  CHECK_MSG(med < 1.2 && p95 < 4.0, "median %.3f C, p95 %.3f C", med, p95);
  CHECK_MSG(share > 0.5, "only %.1f %% of observed texels compared", 100 * share);
  /* a broken correspondence fails those bounds */
  {
    hearth_truth_match tm = {0};
    snprintf(path, sizeof path, "%s/instances/cup_01/derived/hot/mask.npy", root);
    hearth_npy mask = {0};
    CHECK_OK(hearth_npy_read(path, &mask, &err), &err);
    CHECK_OK(hearth_truth_match_state(root, "cup_01", "hot", mask.shape[0], NULL, &tm, &err), &err);
    hearth_similarity S = tm.alignment.ref_from_est, turned = S, moved = S;
    hearth_truth_match_free(&tm);
    hearth_npy_free(&mask);
    /* turned: 90 degrees about the derived frame's z (the turntable axis) */
    const double Rz[9] = {0, -1, 0, 1, 0, 0, 0, 0, 1};
    hearth_mat3_mul(S.T.R, Rz, turned.T.R);
    double bmed, bp95, bshare;
    figures(root, &turned, &bmed, &bp95, &bshare);
    printf("turned 90 degrees: median %.3f C, p95 %.3f C\n", bmed, bp95);
    CHECK_MSG(!(bmed < 1.2 && bp95 < 4.0), "turned frame passes: median %.3f, p95 %.3f", bmed,
              bp95);
    moved.T.t[0] += 0.015;
    figures(root, &moved, &bmed, &bp95, &bshare);
    printf("moved 15 mm: median %.3f C, p95 %.3f C\n", bmed, bp95);
    CHECK_MSG(!(bmed < 1.2 && bp95 < 4.0), "moved frame passes: median %.3f, p95 %.3f", bmed, bp95);
  }

  /* the report: the same figures per state, a contact picture */
  hearth_report rep;
  snprintf(path, sizeof path, "%s/report", base);
  CHECK_OK(hearth_report_write(root, path, "recon truth", NULL, &rep, &err), &err);
  CHECK(rep.n == 1 && rep.entries[0].has_corr && !rep.entries[0].same_uvs);
  if (rep.n == 1) {
    const hearth_report_entry *e = &rep.entries[0];
    CHECK_NEAR(e->corr_app_median_abs_c, med, 0.02);
    CHECK_NEAR(e->corr_share, share, 0.01);
    /* the texel-wise figures go through the resampled truth as well */
    CHECK_MSG(e->has_truth && e->has_apparent && e->app_median_abs_c < 1.2, "median %.3f C",
              e->app_median_abs_c);
  }
  hearth_report_free(&rep);
  snprintf(path, sizeof path, "%s/report/cup_01_hot_contact.png", base);
  hearth_image pic = {0};
  CHECK_OK(hearth_png_read(path, &pic, &err), &err);
  CHECK(pic.width == 1024 && pic.height == 512);
  hearth_image_free(&pic);

  /* recon/ without the build's stamp is another tool's: never reconstructed */
  snprintf(path, sizeof path, "%s/instances/cup_01/derived/.stamps/recon.json", root);
  CHECK(remove(path) == 0);
  snprintf(cmd, sizeof cmd, "'%s' build '%s' --force --dry-run", HEARTH_EXE, root);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0 && !strstr(out, "recon") && strstr(out, "cup_01 scale: would run"),
            "dry run: %s", out);

  /* a failing reconstruction names the instance and the step */
  snprintf(cmd, sizeof cmd,
           "rm -rf '%s/instances/cup_01/recon' '%s/instances/cup_01/derived' && "
           "mv '%s/calibration/factory.json' '%s/calibration/factory.moved'",
           root, root, root, root);
  CHECK(system(cmd) == 0);
  snprintf(cmd, sizeof cmd, "'%s' build '%s' --quiet", HEARTH_EXE, root);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 1 && strstr(out, "cup_01: FAILED in recon: cup_01: recon") &&
                strstr(out, "factory.json"),
            "exit %d: %s", rc, out);
  TEST_MAIN_END();
}
