/* Pose refinement on a hot box in front of an ambient background: thermal
 * images rendered in the test (4x4 supersampled analytic ray-box casts
 * through the distorting lens), poses perturbed by 1 degree and 5 mm. */
#include "hearth/hearth.h"
#include "refine_scene.h"
#include "test_util.h"

#define NV 3
static const double LO[3] = {-0.04, -0.03, 0.0}, HI[3] = {0.05, 0.035, 0.11};

static void render(const hearth_camera *cam, const hearth_rigid *T, double hot, hearth_image *img) {
  hearth_image_alloc(img, (size_t)cam->width, (size_t)cam->height, 1, HEARTH_PIX_F32, NULL);
  float *p = img->data;
  for (int y = 0; y < cam->height; y++)
    for (int x = 0; x < cam->width; x++) {
      double acc = 0;
      for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
          double d[3], dw[3];
          hearth_camera_ray(cam, x - 0.375 + 0.25 * i, y - 0.375 + 0.25 * j, d);
          hearth_rigid_rotate(T, d, dw);
          acc += isfinite(scene_ray_box(T->t, dw, LO, HI)) ? hot : 22.0;
        }
      p[y * cam->width + x] = (float)(acc / 16);
    }
}

int main(void) {
  hearth_camera cam = {256, 192, 275.0, 274.0, 128.5, 95.5, {-0.12, 0.05, 2e-4, -1e-4, 0.0}};
  hearth_mesh mesh = {0};
  scene_box_mesh(&mesh, LO, HI);
  hearth_err err = {0};
  hearth_raycaster *rc = NULL;
  CHECK_OK(hearth_raycaster_new(&mesh, &rc, &err), &err);
  hearth_image imgs[2][NV] = {{{0}}};
  hearth_rigid truth[NV];
  hearth_map_view views[2][NV];
  hearth_rng rng;
  hearth_rng_seed(&rng, 3);
  for (int v = 0; v < NV; v++) {
    double a = 0.7 + 2.0 * v, c[3] = {0.35 * cos(a), 0.35 * sin(a), 0.22},
           tgt[3] = {0.005, 0.0, 0.05};
    scene_look_at(c, tgt, &truth[v]);
    render(&cam, &truth[v], 55.0, &imgs[0][v]);
    render(&cam, &truth[v], 22.0, &imgs[1][v]); /* no contrast at all */
    hearth_rigid start = scene_nudged_start(&truth[v], 1.0, 5.0, &rng);
    views[0][v] = (hearth_map_view){&imgs[0][v], start};
    views[1][v] = (hearth_map_view){&imgs[1][v], start};
  }
  hearth_refine_opts o;
  hearth_refine_opts_default(&o);
  hearth_refine_view_result res[NV], res1[NV];
  CHECK_OK(hearth_refine_views(&mesh, rc, &cam, views[0], NV, &o, res, &err), &err);
  for (int v = 0; v < NV; v++) {
    double e0 = 0, e1 = 0;
    CHECK_OK(hearth_reprojection_error(rc, &cam, &truth[v], &views[0][v].T_world_from_cam, 1, &e0,
                                       &err),
             &err);
    CHECK_OK(hearth_reprojection_error(rc, &cam, &truth[v], &res[v].T_world_from_cam, 1, &e1, &err),
             &err);
    printf(
        "view %d: %s, reprojection %.3f -> %.3f px, criterion %.4f -> %.4f, confidence %.2f, %.1f ms\n",
        v, res[v].reason, e0, e1, res[v].cost_start, res[v].cost_final, res[v].confidence,
        1e3 * res[v].seconds);
    CHECK(e0 > 2.0);
    CHECK(res[v].accepted);
    CHECK(e1 < 0.3);
    CHECK(res[v].cost_final < res[v].cost_start);
    /* the criterion of the returned pose, evaluated independently */
    double cf;
    CHECK_OK(hearth_refine_cost(&mesh, rc, &cam, &imgs[0][v], &res[v].T_world_from_cam, &cf, &err),
             &err);
    CHECK_NEAR(cf, res[v].cost_final, 1e-9);
  }
  /* deterministic whatever the thread count */
  o.threads = 1;
  CHECK_OK(hearth_refine_views(&mesh, rc, &cam, views[0], NV, &o, res1, &err), &err);
  for (int v = 0; v < NV; v++)
    CHECK(!memcmp(&res1[v].T_world_from_cam, &res[v].T_world_from_cam, sizeof(hearth_rigid)));
  /* no contrast: every pose is returned unchanged */
  CHECK_OK(hearth_refine_views(&mesh, rc, &cam, views[1], NV, &o, res, &err), &err);
  for (int v = 0; v < NV; v++) {
    CHECK(!res[v].accepted);
    CHECK(!memcmp(&res[v].T_world_from_cam, &views[1][v].T_world_from_cam, sizeof(hearth_rigid)));
    CHECK(strstr(res[v].reason, "contrast") != NULL);
  }
  /* nudges: parse, closed form of the applied motion, errors */
  hearth_pose_nudge n;
  CHECK_OK(hearth_pose_nudge_parse("hot/v03:0,0,90,10,0,-5", &n, &err), &err);
  CHECK(!strcmp(n.state, "hot") && !strcmp(n.view, "v03"));
  hearth_rigid T;
  hearth_rigid_identity(&T);
  hearth_pose_nudge_apply(&n, &T);
  /* 90 degrees about z maps x to y; translation in the camera frame, metres */
  CHECK_NEAR(T.R[3 * 1 + 0], 1.0, 1e-12);
  CHECK_NEAR(T.t[0], 0.010, 1e-12);
  CHECK_NEAR(T.t[2], -0.005, 1e-12);
  CHECK(hearth_pose_nudge_parse("hot/v03:1,2,3", &n, &err) == HEARTH_E_PARSE);
  CHECK(strstr(err.msg, "hot/v03:1,2,3") != NULL);
  CHECK(hearth_pose_nudge_parse("warmish/v03:0,0,0,0,0,0", &n, &err) == HEARTH_E_PARSE);
  CHECK(hearth_pose_nudge_parse("hot/v03:0,0,x,0,0,0", &n, &err) == HEARTH_E_PARSE);
  /* nudge file: errors name the file and the JSON path */
  const char *dir = test_tmpdir("refine_nudges");
  char path[1200];
  snprintf(path, sizeof path, "%s/n.json", dir);
  const char *bad =
      "{\"views\": [{\"state\": \"hot\", \"view\": \"v01\", \"d_rot_deg\": [0, \"1\", 0]}]}";
  CHECK_OK(hearth_write_file_atomic(path, bad, strlen(bad), &err), &err);
  hearth_pose_nudge *nn = NULL;
  size_t nn_n = 0;
  CHECK(hearth_pose_nudges_read(path, &nn, &nn_n, &err) == HEARTH_E_PARSE);
  CHECK(strstr(err.msg, "n.json") && strstr(err.msg, "views[0].d_rot_deg[1]"));
  const char *good =
      "{\"views\": [{\"state\": \"hot\", \"view\": \"v01\", \"d_rot_deg\": [0, 1, 0], \"d_t_mm\": [1, 2, 3]}]}";
  CHECK_OK(hearth_write_file_atomic(path, good, strlen(good), &err), &err);
  CHECK_OK(hearth_pose_nudges_read(path, &nn, &nn_n, &err), &err);
  CHECK(nn_n == 1 && nn && nn[0].d_rot_deg[1] == 1.0 && nn[0].d_t_mm[2] == 3.0);
  free(nn);
  for (int v = 0; v < NV; v++) {
    hearth_image_free(&imgs[0][v]);
    hearth_image_free(&imgs[1][v]);
  }
  hearth_raycaster_free(rc);
  hearth_mesh_free(&mesh);
  return g_test_failures;
}
