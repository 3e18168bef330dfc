/* off-screen rendering of the three views: front RGB, front thermal
 * (object-attached Turbo textures, unlit; everything else at room
 * temperature), wrist RGB, and the segmentation renders of the audits.
 * Two renderers: hearth's own software rasteriser (sim_soft.c, the
 * default: deterministic bytes, no GL) and MuJoCo's OpenGL renderer
 * (shadows, large images). Two GL back ends: an
 * OSMesa context (CPU, linked) and EGL (a GPU through the device platform,
 * else Mesa's surfaceless platform), loaded at run time so that machines
 * without libEGL still run the CPU path. MuJoCo resolves GL entry points
 * through eglGetProcAddress when libEGL is in the global scope and through
 * OSMesaGetProcAddress otherwise, so one process uses one back end. */
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/geom.h"
#include "sim/sim_env.h"
#include "sim/sim_soft.h"

typedef struct egl_api {
  void *lib;
  PFNEGLGETPROCADDRESSPROC get_proc;
  PFNEGLQUERYDEVICESEXTPROC query_devices;
  PFNEGLQUERYDEVICESTRINGEXTPROC query_device_string;
  PFNEGLGETPLATFORMDISPLAYEXTPROC platform_display;
  PFNEGLINITIALIZEPROC initialize;
  PFNEGLBINDAPIPROC bind_api;
  PFNEGLCHOOSECONFIGPROC choose_config;
  PFNEGLCREATECONTEXTPROC create_context;
  PFNEGLDESTROYCONTEXTPROC destroy_context;
  PFNEGLMAKECURRENTPROC make_current;
  PFNEGLQUERYSTRINGPROC query_string;
  PFNEGLGETERRORPROC get_error;
} egl_api;

struct sim_render {
  int kind; /* SIM_RENDER_SOFT, _GL or _NONE */
  sim_soft *sw;
  unsigned char *th_geom; /* ngeom flags: the assets' thermal geoms */
  int *twin_tex;          /* ngeom: thermal texture of each colour mesh geom, else -1 */
  int twin_ok;            /* thermal view drawn in the RGB view's pass */
  int *ids;               /* width*height geom ids of a segmentation render */
  int egl;
  OSMesaContext gl;
  unsigned char *glbuf;
  egl_api api;
  EGLDisplay dpy;
  EGLContext ctx;
  char renderer[160];
  mjvScene scn;
  mjvCamera cam;
  mjvOption opt;
  mjrContext con;
  int have_scn, have_con;
  uint8_t *front, *thermal, *wrist, *seg; /* width*height*3 */
};

enum { VIEW_RGB = 0, VIEW_THERMAL = 1, VIEW_SEGMENT = 2 };

static int make_current(hearth_sim_env *e) {
  sim_render *r = e->rnd;
  if (r->egl)
    return r->api.make_current(r->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, r->ctx) == EGL_TRUE;
  return OSMesaMakeCurrent(r->gl, r->glbuf, GL_UNSIGNED_BYTE, e->width, e->height) != 0;
}

static hearth_status egl_load(egl_api *a, hearth_err *err) {
  a->lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_GLOBAL);
  if (!a->lib)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "sim: EGL renderer: libEGL.so.1 not found (Debian: libegl1 libegl-mesa0)");
  a->get_proc = (PFNEGLGETPROCADDRESSPROC)dlsym(a->lib, "eglGetProcAddress");
  if (!a->get_proc)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "sim: libEGL.so.1 has no eglGetProcAddress");
#define EGL_FN(field, type, name)            \
  if (!(a->field = (type)a->get_proc(name))) \
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "sim: EGL renderer: %s not available", name);
  EGL_FN(initialize, PFNEGLINITIALIZEPROC, "eglInitialize")
  EGL_FN(bind_api, PFNEGLBINDAPIPROC, "eglBindAPI")
  EGL_FN(choose_config, PFNEGLCHOOSECONFIGPROC, "eglChooseConfig")
  EGL_FN(create_context, PFNEGLCREATECONTEXTPROC, "eglCreateContext")
  EGL_FN(destroy_context, PFNEGLDESTROYCONTEXTPROC, "eglDestroyContext")
  EGL_FN(make_current, PFNEGLMAKECURRENTPROC, "eglMakeCurrent")
  EGL_FN(query_string, PFNEGLQUERYSTRINGPROC, "eglQueryString")
  EGL_FN(get_error, PFNEGLGETERRORPROC, "eglGetError")
  EGL_FN(platform_display, PFNEGLGETPLATFORMDISPLAYEXTPROC, "eglGetPlatformDisplayEXT")
#undef EGL_FN
  /* optional: without device enumeration only the surfaceless platform */
  a->query_devices = (PFNEGLQUERYDEVICESEXTPROC)a->get_proc("eglQueryDevicesEXT");
  a->query_device_string = (PFNEGLQUERYDEVICESTRINGEXTPROC)a->get_proc("eglQueryDeviceStringEXT");
  return HEARTH_OK;
}

/* a display with desktop OpenGL: the first hardware device, else Mesa's
 * surfaceless platform (llvmpipe on a machine without a GPU) */
static hearth_status egl_open(sim_render *r, hearth_err *err) {
  egl_api *a = &r->api;
  hearth_status st = egl_load(a, err);
  if (st) return st;
  r->dpy = EGL_NO_DISPLAY;
  const char *kind = "";
  if (a->query_devices && a->query_device_string) {
    EGLDeviceEXT dev[16];
    EGLint n = 0;
    if (a->query_devices(16, dev, &n) == EGL_TRUE) {
      for (EGLint i = 0; i < n && r->dpy == EGL_NO_DISPLAY; i++) {
        const char *ext = a->query_device_string(dev[i], EGL_EXTENSIONS);
        if (ext && strstr(ext, "EGL_MESA_device_software")) continue;
        EGLDisplay d = a->platform_display(EGL_PLATFORM_DEVICE_EXT, dev[i], NULL);
        if (d != EGL_NO_DISPLAY && a->initialize(d, NULL, NULL) == EGL_TRUE)
          r->dpy = d, kind = "device";
      }
    }
  }
  if (r->dpy == EGL_NO_DISPLAY) {
    EGLDisplay d = a->platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (d != EGL_NO_DISPLAY && a->initialize(d, NULL, NULL) == EGL_TRUE)
      r->dpy = d, kind = "surfaceless";
  }
  if (r->dpy == EGL_NO_DISPLAY)
    return hearth_err_set(
        err, HEARTH_E_UNSUPPORTED,
        "sim: EGL renderer: no GPU device and no surfaceless platform (EGL error 0x%x)",
        (unsigned)a->get_error());
  const char *ext = a->query_string(r->dpy, EGL_EXTENSIONS);
  if (!ext || !strstr(ext, "EGL_KHR_surfaceless_context"))
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "sim: EGL renderer: display lacks EGL_KHR_surfaceless_context");
  if (a->bind_api(EGL_OPENGL_API) != EGL_TRUE)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "sim: EGL renderer: desktop OpenGL not available");
  const EGLint want[] = {EGL_RED_SIZE,     8,  EGL_GREEN_SIZE,      8,
                         EGL_BLUE_SIZE,    8,  EGL_ALPHA_SIZE,      8,
                         EGL_DEPTH_SIZE,   24, EGL_STENCIL_SIZE,    8,
                         EGL_SURFACE_TYPE, 0,  EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                         EGL_NONE};
  EGLConfig cfg;
  EGLint ncfg = 0;
  if (a->choose_config(r->dpy, want, &cfg, 1, &ncfg) != EGL_TRUE || ncfg < 1)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "sim: EGL renderer: no RGBA8/depth24 OpenGL config");
  /* MuJoCo's renderer uses the compatibility profile (the default) */
  r->ctx = a->create_context(r->dpy, cfg, EGL_NO_CONTEXT, NULL);
  if (r->ctx == EGL_NO_CONTEXT)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "sim: EGL renderer: context creation failed (0x%x)",
                          (unsigned)a->get_error());
  if (a->make_current(r->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, r->ctx) != EGL_TRUE)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "sim: EGL renderer: eglMakeCurrent failed (0x%x)",
                          (unsigned)a->get_error());
  typedef const unsigned char *(*get_string_fn)(unsigned);
  get_string_fn gs = (get_string_fn)a->get_proc("glGetString");
  const unsigned char *name = gs ? gs(GL_RENDERER) : NULL;
  snprintf(r->renderer, sizeof r->renderer, "egl %s: %s", kind, name ? (const char *)name : "?");
  return HEARTH_OK;
}

/* whether the thermal view can come from the RGB view's pass: the
 * colour meshes (group 2) and thermal meshes (group 3) are exactly the
 * assets' pairs, each pair the same mesh at the same pose */
static void twin_setup(hearth_sim_env *e) {
  sim_render *r = e->rnd;
  const mjModel *m = e->m;
  int ok = 1, n2 = 0, n3 = 0;
  for (int g = 0; g < m->ngeom; g++) {
    r->twin_tex[g] = -1;
    n2 += m->geom_group[g] == 2, n3 += m->geom_group[g] == 3;
  }
  for (int k = 0; k < SIM_NOBJ && ok; k++) {
    int a = e->obj_geom_rgb[k], b = e->obj_geom_th[k];
    ok = a >= 0 && b >= 0 && m->geom_group[a] == 2 && m->geom_group[b] == 3 &&
         m->geom_type[a] == m->geom_type[b] && m->geom_dataid[a] == m->geom_dataid[b] &&
         m->geom_bodyid[a] == m->geom_bodyid[b] &&
         memcmp(m->geom_pos + 3 * a, m->geom_pos + 3 * b, 3 * sizeof(mjtNum)) == 0 &&
         memcmp(m->geom_quat + 4 * a, m->geom_quat + 4 * b, 4 * sizeof(mjtNum)) == 0 &&
         m->geom_matid[b] >= 0 && m->mat_texid[m->geom_matid[b]] >= 0;
    if (ok) r->twin_tex[a] = m->mat_texid[m->geom_matid[b]];
  }
  r->twin_ok = ok && n2 == SIM_NOBJ && n3 == SIM_NOBJ;
}

hearth_status sim_render_init(hearth_sim_env *e, hearth_err *err) {
  sim_render *r = calloc(1, sizeof *r);
  if (!r) return hearth_err_set(err, HEARTH_E_NOMEM, "sim: out of memory");
  e->rnd = r;
  r->kind = e->render_kind;
  size_t px = (size_t)e->width * (size_t)e->height;
  r->front = malloc(px * 3), r->thermal = malloc(px * 3), r->wrist = malloc(px * 3),
  r->seg = malloc(px * 3), r->ids = malloc(px * sizeof(int));
  r->th_geom = calloc((size_t)e->m->ngeom + 1, 1);
  r->twin_tex = malloc(sizeof(int) * ((size_t)e->m->ngeom + 1));
  if (!r->front || !r->thermal || !r->wrist || !r->seg || !r->ids || !r->th_geom || !r->twin_tex)
    return hearth_err_set(err, HEARTH_E_NOMEM, "sim: out of memory for %dx%d images", e->width,
                          e->height);
  for (int k = 0; k < SIM_NOBJ; k++)
    if (e->obj_geom_th[k] >= 0) r->th_geom[e->obj_geom_th[k]] = 1;
  if (r->kind == SIM_RENDER_NONE) {
    snprintf(r->renderer, sizeof r->renderer, "none");
    return HEARTH_OK;
  }
  if (r->kind == SIM_RENDER_SOFT) {
    twin_setup(e);
    if (!(r->sw = sim_soft_new(e->m, e->width, e->height)))
      return hearth_err_set(err, HEARTH_E_NOMEM, "sim: out of memory for the software renderer");
    snprintf(r->renderer, sizeof r->renderer, "soft: hearth rasteriser %s", SIM_SOFT_VERSION);
    return HEARTH_OK;
  }
  r->egl = strcmp(e->gl, "egl") == 0;
  if (r->egl) {
    hearth_status st = egl_open(r, err);
    if (st) return st;
  } else {
    r->glbuf = malloc(px * 4);
    if (!r->glbuf)
      return hearth_err_set(err, HEARTH_E_NOMEM, "sim: out of memory for %dx%d images", e->width,
                            e->height);
    r->gl = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, NULL);
    if (!r->gl)
      return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "sim: OSMesa context creation failed");
    if (!make_current(e))
      return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "sim: OSMesaMakeCurrent failed");
    const GLubyte *name = glGetString(GL_RENDERER);
    snprintf(r->renderer, sizeof r->renderer, "osmesa: %s", name ? (const char *)name : "?");
  }
  mjv_defaultScene(&r->scn);
  mjv_defaultCamera(&r->cam);
  mjv_defaultOption(&r->opt);
  mjr_defaultContext(&r->con);
  mjv_makeScene(e->m, &r->scn, 2000);
  r->have_scn = 1;
  mjr_makeContext(e->m, &r->con, mjFONTSCALE_100);
  r->have_con = 1;
  mjr_setBuffer(mjFB_OFFSCREEN, &r->con);
  if (r->con.currentBuffer != mjFB_OFFSCREEN)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "sim: no off-screen framebuffer");
  return HEARTH_OK;
}

const char *hearth_sim_renderer(const hearth_sim_env *e) {
  return e && e->rnd ? e->rnd->renderer : "";
}

void sim_render_free(hearth_sim_env *e) {
  sim_render *r = e->rnd;
  if (!r) return;
  sim_soft_free(r->sw);
  free(r->th_geom), free(r->ids), free(r->twin_tex);
  if (r->kind != SIM_RENDER_GL) {
    free(r->front), free(r->thermal), free(r->wrist), free(r->seg);
    free(r);
    e->rnd = NULL;
    return;
  }
  int current =
      (r->egl ? r->ctx != NULL && r->ctx != EGL_NO_CONTEXT : r->gl != NULL) && make_current(e);
  if (current && r->have_con) mjr_freeContext(&r->con);
  if (r->have_scn) mjv_freeScene(&r->scn);
  if (r->egl) {
    if (r->api.make_current && r->dpy != EGL_NO_DISPLAY)
      r->api.make_current(r->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (r->ctx != NULL && r->ctx != EGL_NO_CONTEXT) r->api.destroy_context(r->dpy, r->ctx);
    /* the display stays initialised: EGL displays are per process, not per
     * env (terminating it would pull it from under another env), and
     * libEGL stays loaded: MuJoCo holds its entry points */
  } else {
    /* unbind before destroying so Mesa can release the context's buffer */
    if (r->gl) OSMesaMakeCurrent(NULL, NULL, GL_UNSIGNED_BYTE, 0, 0);
    if (r->gl) OSMesaDestroyContext(r->gl);
  }
  free(r->glbuf);
  free(r->front), free(r->thermal), free(r->wrist), free(r->seg);
  free(r);
  e->rnd = NULL;
}

static int is_obj_geom(const hearth_sim_env *e, int g, const int *list) {
  for (int k = 0; k < SIM_NOBJ; k++)
    if (list[k] == g) return 1;
  return 0;
}

/* the thermal view's colour of everything but the assets: the room
 * colour as MuJoCo's GL path shows an emissive (1) unlit surface with
 * no light in the scene, which adds its 0.3 global ambient */
static void room_shown(uint8_t out[3]) {
  uint8_t room[3];
  sim_room_rgb(room);
  for (int c = 0; c < 3; c++) {
    float v = 1.3f * (room[c] / 255.0f);
    out[c] = (uint8_t)((v > 1 ? 1 : v) * 255.0f + 0.5f);
  }
}

/* one camera with the software renderer; ids (may be NULL) gets geom ids */
static void soft_view(hearth_sim_env *e, int cam, int mode, int only_geom, uint8_t *out, int *ids) {
  sim_render *r = e->rnd;
  sim_soft_view v = {.cam = cam, .only_geom = only_geom, .tex_geom = r->th_geom};
  v.mode = mode == VIEW_RGB       ? SIM_SOFT_LIT
           : mode == VIEW_THERMAL ? SIM_SOFT_UNLIT
                                  : SIM_SOFT_SEGMENT;
  /* MuJoCo's default groups 0-2; the thermal view swaps group 2 (colour
   * meshes) for 3 (thermal meshes) */
  v.groups[0] = v.groups[1] = 1;
  v.groups[2] = mode != VIEW_THERMAL;
  v.groups[3] = mode == VIEW_THERMAL;
  room_shown(v.flat_rgb);
  sim_soft_render(r->sw, e->m, e->d, &v, out, NULL, ids);
}

/* render one camera; `only_geom` >= 0 keeps just that model geom */
static void render_view(hearth_sim_env *e, int cam, int mode, int only_geom, uint8_t *out) {
  sim_render *r = e->rnd;
  mjModel *m = e->m;
  if (r->kind == SIM_RENDER_SOFT) {
    soft_view(e, cam, mode, only_geom, out, NULL);
    return;
  }
  make_current(e);
  r->cam.type = mjCAMERA_FIXED;
  r->cam.fixedcamid = cam;
  r->opt.geomgroup[2] = mode != VIEW_THERMAL;
  r->opt.geomgroup[3] = mode == VIEW_THERMAL;
  mjv_updateScene(m, e->d, &r->opt, NULL, &r->cam, mjCAT_ALL, &r->scn);
  mjvScene *s = &r->scn;
  for (int f = 0; f < mjNRNDFLAG; f++) s->flags[f] = 0;
  s->flags[mjRND_CULL_FACE] = 1;
  int headlight = m->vis.headlight.active;
  if (mode == VIEW_RGB) {
    s->flags[mjRND_SHADOW] = e->shadows;
  } else {
    s->nlight = 0;
    m->vis.headlight.active = 0;
  }
  if (mode == VIEW_SEGMENT) s->flags[mjRND_SEGMENT] = s->flags[mjRND_IDCOLOR] = 1;
  if (only_geom >= 0) {
    int n = 0;
    for (int i = 0; i < s->ngeom; i++)
      if (s->geoms[i].objtype == mjOBJ_GEOM && s->geoms[i].objid == only_geom)
        s->geoms[n++] = s->geoms[i];
    s->ngeom = n;
  }
  if (mode == VIEW_THERMAL) {
    /* everything but the assets' thermal geoms shows room temperature,
     * unlit; emission 1 saturates the lighting sum so colours are exact */
    uint8_t room[3];
    sim_room_rgb(room);
    for (int i = 0; i < s->ngeom; i++) {
      mjvGeom *g = &s->geoms[i];
      g->specular = g->shininess = g->reflectance = 0;
      g->emission = 1;
      if (g->objtype == mjOBJ_GEOM && is_obj_geom(e, g->objid, e->obj_geom_th)) {
        g->rgba[0] = g->rgba[1] = g->rgba[2] = g->rgba[3] = 1;
        continue;
      }
      g->texid = -1;
      for (int c = 0; c < 3; c++) g->rgba[c] = room[c] / 255.0f;
      g->rgba[3] = 1;
    }
  }
  mjrRect vp = {0, 0, e->width, e->height};
  mjr_render(vp, s, &r->con);
  mjr_readPixels(out, NULL, vp, &r->con);
  m->vis.headlight.active = headlight;
}

/* model geom id behind a segmentation pixel, -1 for background */
static int seg_geom(const hearth_sim_env *e, const uint8_t *px) {
  int id = px[0] + 256 * px[1] + 65536 * px[2] - 1;
  const mjvScene *s = &e->rnd->scn;
  if (id < 0) return -1;
  /* segid survives the compaction done for single-geom renders */
  if (id < s->ngeom && s->geoms[id].segid == id)
    return s->geoms[id].objtype == mjOBJ_GEOM ? s->geoms[id].objid : -1;
  for (int i = 0; i < s->ngeom; i++)
    if (s->geoms[i].segid == id) return s->geoms[i].objtype == mjOBJ_GEOM ? s->geoms[i].objid : -1;
  return -1;
}

void sim_render_texture_changed(hearth_sim_env *e, int texid) {
  sim_render *r = e->rnd;
  if (!r || texid < 0) return;
  if (r->kind == SIM_RENDER_SOFT) sim_soft_update_tex(r->sw, e->m, texid);
  else if (r->kind == SIM_RENDER_GL && r->have_con && make_current(e))
    mjr_uploadTexture(e->m, &r->con, texid);
}

hearth_status hearth_sim_observe(hearth_sim_env *e, hearth_sim_obs *o, hearth_err *err) {
  sim_render *r = e->rnd;
  memset(o, 0, sizeof *o);
  /* dynamic temperatures: the thermal textures from the current state */
  if (r->kind != SIM_RENDER_NONE) sim_thermal_update_textures(e);
  o->width = e->width, o->height = e->height;
  if (r->kind == SIM_RENDER_SOFT && r->twin_ok) {
    /* one pass draws the front RGB view and, from the same surfaces, the
     * thermal one */
    sim_soft_view v = {.cam = e->cam_front,
                       .mode = SIM_SOFT_LIT,
                       .only_geom = -1,
                       .twin_tex = r->twin_tex,
                       .groups = {1, 1, 1, 0, 0, 0}};
    room_shown(v.flat_rgb);
    sim_soft_render(r->sw, e->m, e->d, &v, r->front, r->thermal, NULL);
    o->agentview_rgb = r->front, o->agentview_thermal = r->thermal;
  } else if (r->kind != SIM_RENDER_NONE) {
    render_view(e, e->cam_front, VIEW_RGB, -1, r->front);
    render_view(e, e->cam_front, VIEW_THERMAL, -1, r->thermal);
    o->agentview_rgb = r->front, o->agentview_thermal = r->thermal;
  }
  if (e->render_wrist && r->kind != SIM_RENDER_NONE) {
    render_view(e, e->cam_wrist, VIEW_RGB, -1, r->wrist);
    o->eye_in_hand_rgb = r->wrist;
  }
  const mjData *d = e->d;
  for (int i = 0; i < 7; i++) o->joint_states[i] = d->qpos[e->arm_qadr[i]];
  for (int s = 0; s < 2; s++) o->gripper_states[s] = d->qpos[e->fing_qadr[s]] * (s ? -1 : 1);
  for (int i = 0; i < 3; i++) o->ee_pos[i] = d->site_xpos[3 * e->site_grip + i];
  const double *R = d->site_xmat + 9 * e->site_grip;
  hearth_matrix_to_rotvec(R, o->ee_ori);
  mju_mat2Quat(o->ee_quat, R);
  return HEARTH_OK;
}

/* a segmentation render of the front camera into r->ids: the model geom
 * of every pixel, -1 for background; `only_geom` >= 0 draws just it */
static hearth_status render_ids(hearth_sim_env *e, int only_geom, hearth_err *err) {
  sim_render *r = e->rnd;
  if (r->kind == SIM_RENDER_NONE)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "sim: segmentation needs a renderer (this env renders none)");
  if (r->kind == SIM_RENDER_SOFT) {
    soft_view(e, e->cam_front, VIEW_SEGMENT, only_geom, NULL, r->ids);
    return HEARTH_OK;
  }
  render_view(e, e->cam_front, VIEW_SEGMENT, only_geom, r->seg);
  size_t n = (size_t)e->width * (size_t)e->height;
  for (size_t i = 0; i < n; i++) r->ids[i] = seg_geom(e, r->seg + 3 * i);
  return HEARTH_OK;
}

static long count_geom(const hearth_sim_env *e, int geom, int box[4]) {
  const int *ids = e->rnd->ids;
  long n = 0;
  if (box) box[0] = box[1] = 1 << 30, box[2] = box[3] = -1;
  for (int y = 0; y < e->height; y++)
    for (int x = 0; x < e->width; x++)
      if (ids[(size_t)y * e->width + x] == geom) {
        n++;
        if (box) {
          if (x < box[0]) box[0] = x;
          if (y < box[1]) box[1] = y;
          if (x > box[2]) box[2] = x;
          if (y > box[3]) box[3] = y;
        }
      }
  return n;
}

hearth_status hearth_sim_visibility(hearth_sim_env *e, double *tf, double *of, hearth_err *err) {
  double frac[2];
  long vis[2];
  /* pixels seen in the whole scene, then each candidate rendered alone */
  hearth_status st = render_ids(e, -1, err);
  if (st) return st;
  for (int c = 0; c < 2; c++)
    vis[c] = count_geom(e, e->obj_geom_rgb[c == 0 ? e->target : 1 - e->target], NULL);
  for (int c = 0; c < 2; c++) {
    int g = e->obj_geom_rgb[c == 0 ? e->target : 1 - e->target];
    if ((st = render_ids(e, g, err))) return st;
    long all = count_geom(e, g, NULL);
    frac[c] = all > 0 ? (double)vis[c] / (double)all : 0.0;
  }
  if (tf) *tf = frac[0];
  if (of) *of = frac[1];
  return HEARTH_OK;
}

hearth_status hearth_sim_candidate_boxes(hearth_sim_env *e, int boxes[2][4], hearth_err *err) {
  if (sim_task_get(e->task)->handles) {
    sim_handles_boxes(e, boxes);
    return HEARTH_OK;
  }
  hearth_status st = render_ids(e, -1, err);
  if (st) return st;
  for (int slot = 0; slot < 2; slot++) {
    int k = slot ^ e->swap;
    if (count_geom(e, e->obj_geom_rgb[k], boxes[slot]) == 0)
      return hearth_err_set(err, HEARTH_E_NOT_FOUND, "sim: candidate in slot %c not visible",
                            'A' + slot);
  }
  return HEARTH_OK;
}
