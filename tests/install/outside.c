/* An outside program built against an installed hearth with nothing but
 * `pkg-config --cflags --libs hearth`: it includes the umbrella header and
 * calls into every pipeline area (core, io, dataset, net, mesh, synth,
 * calib, poses, map, release), so a missing library or a wrong link order
 * fails to link. Usage: outside WORK_DIR. Exit 0 when every check holds. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/hearth.h"

static int failures = 0;
#define EXPECT(cond)                                                   \
  do {                                                                 \
    if (!(cond)) {                                                     \
      fprintf(stderr, "outside.c:%d: expected %s\n", __LINE__, #cond); \
      failures++;                                                      \
    }                                                                  \
  } while (0)

/* core + io: a 4 x 3 thermal CSV written and read back */
static void check_csv(const char *dir) {
  char path[4096];
  EXPECT(hearth_path_join(path, sizeof path, dir, "tiny.csv") == HEARTH_OK);
  hearth_image t = {0}, back = {0};
  hearth_err err = {0};
  EXPECT(hearth_image_alloc(&t, 4, 3, 1, HEARTH_PIX_F32, &err) == HEARTH_OK);
  float *v = t.data;
  for (int i = 0; i < 12; i++) v[i] = 20.0f + 0.25f * (float)i;
  EXPECT(hearth_thermal_write_csv(path, &t, 2, &err) == HEARTH_OK);
  hearth_csv_opts o;
  hearth_csv_opts_default(&o);
  o.width = 4;
  o.height = 3;
  if (hearth_thermal_read_csv(path, &o, &back, &err) != HEARTH_OK) {
    fprintf(stderr, "outside: %s\n", err.msg);
    failures++;
  } else {
    EXPECT(back.width == 4 && back.height == 3);
    for (int i = 0; i < 12; i++) EXPECT(((float *)back.data)[i] == v[i]);
  }
  hearth_image_free(&t);
  hearth_image_free(&back);
  /* the strict reader names the file and the place of a bad cell */
  const char bad[] = "1,2\n3,x\n";
  hearth_image none = {0};
  EXPECT(hearth_thermal_parse_csv(bad, sizeof bad - 1, "bad.csv", NULL, &none, &err) != HEARTH_OK);
  EXPECT(strstr(err.msg, "bad.csv") != NULL);
  hearth_image_free(&none);
}

/* mesh (Embree): a unit square, encoded as GLB, parsed back, hit by a ray */
static void check_mesh(void) {
  hearth_mesh m = {0}, back = {0};
  hearth_err err = {0};
  EXPECT(hearth_mesh_alloc(&m, 4, 2, 1, &err) == HEARTH_OK);
  const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const float uv[8] = {0, 1, 1, 1, 1, 0, 0, 0};
  const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
  memcpy(m.positions, pos, sizeof pos);
  memcpy(m.uvs, uv, sizeof uv);
  memcpy(m.indices, idx, sizeof idx);
  EXPECT(hearth_mesh_validate(&m, "square", &err) == HEARTH_OK);
  uint8_t *glb = NULL;
  size_t n = 0;
  EXPECT(hearth_glb_encode(&m, &glb, &n, &err) == HEARTH_OK);
  hearth_glb_read_opts ro;
  hearth_glb_read_opts_default(&ro);
  ro.require_uvs = 1;
  EXPECT(glb && hearth_glb_parse(glb, n, "square.glb", &ro, &back, &err) == HEARTH_OK);
  EXPECT(back.n_triangles == 2 && back.uvs != NULL);
  free(glb);
  hearth_raycaster *rc = NULL;
  if (hearth_raycaster_new(&m, &rc, &err) == HEARTH_OK) {
    const double org[3] = {0.25, 0.5, 1.0}, dir[3] = {0, 0, -1};
    hearth_ray_hit hit;
    EXPECT(hearth_raycast(rc, org, dir, 0.0, 10.0, &hit) == 1);
    EXPECT(fabs(hit.t - 1.0) < 1e-5 && hit.front == 1);
    hearth_raycaster_free(rc);
  } else {
    fprintf(stderr, "outside: %s\n", err.msg);
    failures++;
  }
  hearth_mesh_free(&m);
  hearth_mesh_free(&back);
}

/* calib (LAPACK): the pose of the plate seen by a known camera */
static void check_calib(void) {
  hearth_camera cam = {256, 192, 300.0, 300.0, 128.0, 96.0, {0}};
  hearth_rigid T;
  hearth_rigid_identity(&T);
  T.t[0] = -0.05;
  T.t[1] = -0.04;
  T.t[2] = 0.4;
  double obj[HEARTH_PLATE_HOLES][3], img[2 * HEARTH_PLATE_HOLES];
  for (int i = 0; i < HEARTH_PLATE_HOLES; i++) {
    double x[3];
    hearth_plate_hole(i, obj[i]);
    hearth_rigid_apply(&T, obj[i], x);
    EXPECT(hearth_camera_project(&cam, x, img + 2 * i, NULL) == 1);
  }
  hearth_rigid est;
  double rms = -1;
  hearth_err err = {0};
  EXPECT(hearth_calib_pose(&cam, (const double(*)[3])obj, HEARTH_PLATE_HOLES, img, &est, &rms,
                           &err) == HEARTH_OK);
  EXPECT(rms >= 0 && rms < 1e-6);
  EXPECT(fabs(est.t[2] - 0.4) < 1e-6);
}

/* net: a msgpack map round trip */
static void check_msgpack(void) {
  hearth_mp_writer w;
  hearth_mp_writer_init(&w);
  hearth_mp_put_map(&w, 1);
  hearth_mp_put_cstr(&w, "answer");
  hearth_mp_put_int(&w, 42);
  EXPECT(!w.failed);
  hearth_mp_doc doc;
  hearth_err err = {0};
  EXPECT(hearth_mp_decode(w.buf, w.len, NULL, &doc, &err) == HEARTH_OK);
  const hearth_mp_value *v = hearth_mp_map_get(doc.root, "answer", HEARTH_MP_STR);
  EXPECT(v && v->type == HEARTH_MP_INT && v->i == 42);
  hearth_mp_doc_free(&doc);
  hearth_mp_writer_free(&w);
}

/* dataset, synth, poses, map, release: tables, parsers and a validation of
 * a release that is not there */
static void check_stages(const char *dir) {
  EXPECT(hearth_category_valid("cup") && !hearth_category_valid("teapot"));
  const char *names[64];
  EXPECT(hearth_synth_categories(names, 64) > 0);
  hearth_pose_nudge nudge;
  hearth_err err = {0};
  EXPECT(hearth_pose_nudge_parse("hot/v03:0,0,1,0,0,2", &nudge, &err) == HEARTH_OK);
  EXPECT(!strcmp(nudge.state, "hot") && nudge.d_rot_deg[2] == 1.0 && nudge.d_t_mm[2] == 2.0);
  hearth_map_opts mo;
  hearth_map_opts_default(&mo);
  EXPECT(mo.resolution == 1024 && mo.fusion == HEARTH_FUSE_MAX);
  char root[4096];
  EXPECT(hearth_path_join(root, sizeof root, dir, "no-such-release") == HEARTH_OK);
  hearth_validate_opts vo;
  hearth_validate_opts_default(&vo);
  vo.threads = 1;
  hearth_problems probs = {0};
  size_t files = 0;
  EXPECT(hearth_validate_release(root, &vo, &probs, &files, &err) == HEARTH_OK);
  EXPECT(probs.n > 0);
  hearth_problems_free(&probs);
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: outside WORK_DIR\n");
    return 2;
  }
  EXPECT(!strcmp(hearth_status_name(HEARTH_E_PARSE), "HEARTH_E_PARSE"));
  check_csv(argv[1]);
  check_mesh();
  check_calib();
  check_msgpack();
  check_stages(argv[1]);
  if (failures) fprintf(stderr, "outside: %d check(s) failed\n", failures);
  else printf("outside: every check passed\n");
  return failures ? 1 : 0;
}
