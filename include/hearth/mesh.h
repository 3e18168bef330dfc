/* hearth/mesh.h - area mesh (src/mesh/): triangle meshes with UVs, glTF
 * binary (GLB) files, the ray caster (Embree) used by the virtual rig, scale
 * recovery and mapping, a camera's pixel grid cast by rasterisation, and UV
 * islands and texel rasterisation.
 *
 * UVs follow glTF: (0,0) is the top-left of the texture image, v grows
 * downwards, so texel [row][col] of an R x R map has its centre at
 * u = (col + 0.5) / R, v = (row + 0.5) / R. Positions are in metres in
 * metric frames. */
#ifndef HEARTH_MESH_H
#define HEARTH_MESH_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/camera.h"
#include "hearth/core.h"
#include "hearth/geom.h"
#include "hearth/image.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct hearth_mesh {
  size_t n_vertices;
  float *positions; /* 3 * n_vertices */
  float *uvs;       /* 2 * n_vertices, or NULL if the mesh has none */
  size_t n_triangles;
  uint32_t *indices;    /* 3 * n_triangles, counter-clockwise front faces */
  hearth_image texture; /* base colour (RGB/RGBA U8), data NULL if none */
} hearth_mesh;
/* A mesh owns its arrays and its texture's data; every function that fills
 * a hearth_mesh * output allocates them, released with hearth_mesh_free. */

/* Frees the arrays and the texture and zeroes m; accepts a zeroed mesh. */
void hearth_mesh_free(hearth_mesh *m);
/* Allocate (uninitialised) positions, indices and, with with_uvs, uvs for
 * the given counts; no texture. m need not be initialised. */
hearth_status hearth_mesh_alloc(hearth_mesh *m, size_t n_vertices, size_t n_triangles, int with_uvs,
                                hearth_err *err);
/* A deep copy of src, texture included, into dst (overwritten, not freed). */
hearth_status hearth_mesh_copy(const hearth_mesh *src, hearth_mesh *dst, hearth_err *err);
/* Axis-aligned bounds. */
void hearth_mesh_bounds(const hearth_mesh *m, double lo[3], double hi[3]);
/* Apply x' = s R x + t to every vertex. */
void hearth_mesh_transform(hearth_mesh *m, double s, const double R[9], const double t[3]);
/* Check indices in range, finite positions/UVs; HEARTH_E_RANGE with the
 * triangle index otherwise. `name` is used in messages. */
hearth_status hearth_mesh_validate(const hearth_mesh *m, const char *name, hearth_err *err);

/* Vertices welded by position (a UV seam or a hard edge splits one surface
 * point into several vertices): id[v] for each of m's vertices, equal for
 * vertices at bit-identical positions, in 0..n_vertices-1 (the rank of the
 * first of them in position order). HEARTH_E_RANGE naming the vertex if a
 * position is not finite; HEARTH_E_NOMEM. */
hearth_status hearth_mesh_weld_ids(const hearth_mesh *m, uint32_t *id, hearth_err *err);

/* ---- glTF binary ---------------------------------------------------------- */
/* What hearth_glb_read did to the file's UVs, filled on success when
 * hearth_glb_read_opts.report is set. */
typedef struct hearth_glb_report {
  uint32_t uv_islands_moved;      /* islands brought into [0,1]^2 by whole tiles */
  uint32_t uv_islands_mirrored;   /* of those, reflected on an axis (MIRRORED_REPEAT) */
  uint32_t uv_islands_left;       /* left outside [0,1]^2 (only when UVs are not required) */
  size_t uv_triangles_straddling; /* triangles crossing a tile border */
  size_t quantized_primitives;    /* primitives with integer POSITION or UVs */
  size_t transformed_primitives;  /* primitives whose UVs KHR_texture_transform changed */
} hearth_glb_report;

typedef struct hearth_glb_read_opts {
  int require_uvs;           /* fail with HEARTH_E_NOT_FOUND naming the primitive if no UVs */
  int load_texture;          /* decode the base colour texture of the first material if embedded */
  size_t max_triangles;      /* 0: default limit (50 million) */
  int keep_uv_tiles;         /* 1: UVs as stored; 0 (default): islands folded into [0,1]^2 */
  hearth_glb_report *report; /* optional, written on success; NULL: not wanted */
} hearth_glb_read_opts;
/* Defaults (all zero): UVs not required, no texture decoded, the
 * 50-million limit, UV islands folded into [0,1]^2, no report. */
void hearth_glb_read_opts_default(hearth_glb_read_opts *o);

/* Read a GLB: walks the default scene's node hierarchy applying node
 * transforms (matrix or TRS), concatenates every triangle primitive
 * (indexed or not) of every mesh instance into one mesh. Draco/meshopt
 * compression, sparse accessors, non-triangle modes, out-of-range indices
 * and truncated chunks are errors naming the file and the element; so is
 * any extension in extensionsRequired but the two below. Skins and morph
 * targets are not applied (the bind shape is read). opts may be NULL (the
 * defaults). parse reads data[0..size) (copied; `name` names it in messages).
 *
 * UVs. A primitive's UVs are those its material's base colour texture
 * samples: TEXCOORD_n for the textureInfo's texCoord n (0 without a
 * texture), with KHR_texture_transform applied when the textureInfo has
 * it (its texCoord overrides the textureInfo's). The transform is
 * uv' = T(offset) R(rotation) S(scale) uv, scale first:
 *   u' = ox + sx cos(r) u + sy sin(r) v,   v' = oy - sx sin(r) u + sy cos(r) v.
 * That sign is the one of the extension's worked examples, the Khronos
 * sample viewer and Blender (a positive rotation turns the UVs
 * counter-clockwise as seen on the image, v pointing down); the
 * extension's GLSL listing read as column-major has the opposite sign
 * (KhronosGroup/glTF issue 1563).
 *
 * KHR_mesh_quantization (in extensionsUsed or extensionsRequired) allows
 * POSITION and TEXCOORD_n of BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT,
 * normalised or not: normalised values map to [0,1] (c / 255, c / 65535)
 * or [-1,1] (max(c / 127, -1), max(c / 32767, -1)), plain ones to their
 * integer value; the node transform (positions) and the texture transform
 * (UVs) dequantise them, as the extension specifies. Without the
 * extension POSITION is FLOAT and UVs FLOAT or normalised unsigned.
 *
 * UV tiles. UVs outside [0,1] are valid glTF: the default sampler wraps
 * with REPEAT, so the texture at u + k (k an integer) is the texture at u,
 * and exporters write such files (Blender stores v' = 1 - v, so an island
 * anywhere outside Blender's unit square, e.g. a UDIM-style tile, lies
 * outside [0,1] in the file). Maps cover [0,1]^2 only, so unless
 * keep_uv_tiles is set every UV island (triangles joined by shared UV
 * points) that lies in one tile [i, i+1] x [j, j+1] (overhanging it by at
 * most HEARTH_UV_TILE_SLACK) is brought into [0,1]^2, per axis as the
 * wrap mode of its base colour texture's sampler allows:
 *   REPEAT (also: no sampler, no texture): translated by -i;
 *   MIRRORED_REPEAT (period 2, odd tiles mirror tile 0): an even i is
 *     translated by -i, an odd one reflected, u' = i + 1 - u: the same
 *     texel either way;
 *   CLAMP_TO_EDGE: outside [0,1] the lookup repeats the edge texels, so
 *     such an island owns no texels; it is not moved (that would change
 *     what it shows).
 * An island spanning tiles, or clamped outside [0,1]^2, cannot be mapped:
 * with require_uvs that is HEARTH_E_UNSUPPORTED naming the file, the
 * island and triangle counts and a first triangle (mesh, primitive,
 * index); without, such islands stay as stored. Overlaps between islands
 * folded from different tiles are not checked. */
hearth_status hearth_glb_read(const char *path, const hearth_glb_read_opts *opts, hearth_mesh *out,
                              hearth_err *err);
hearth_status hearth_glb_parse(const void *data, size_t size, const char *name,
                               const hearth_glb_read_opts *opts, hearth_mesh *out, hearth_err *err);
/* Write one mesh (POSITION, TEXCOORD_0 if present, NORMAL computed, uint32
 * indices) and, if m->texture is set, an embedded PNG base-colour texture.
 * The file passes the Khronos glTF validator. Atomic. encode writes the
 * same bytes to *out (malloc'ed, the caller frees it). */
hearth_status hearth_glb_write(const char *path, const hearth_mesh *m, hearth_err *err);
hearth_status hearth_glb_encode(const hearth_mesh *m, uint8_t **out, size_t *size, hearth_err *err);
/* As hearth_glb_write, with m->texture's PNG already encoded: tex_png's
 * tex_size bytes (hearth_png_encode of m->texture, so the file is the one
 * hearth_glb_write gives) are embedded as they are, not encoded again. */
hearth_status hearth_glb_write_png(const char *path, const hearth_mesh *m, const uint8_t *tex_png,
                                   size_t tex_size, hearth_err *err);

/* ---- ray casting (Embree) ------------------------------------------------ */
typedef struct hearth_raycaster hearth_raycaster;

typedef struct hearth_ray_hit {
  float t;       /* distance along the (unit) direction */
  uint32_t prim; /* triangle index */
  float b1, b2;  /* barycentrics of vertices 1 and 2 of the triangle */
  int front;     /* 1 if the ray hit the front (counter-clockwise) side */
} hearth_ray_hit;

/* Build an acceleration structure over m (m must outlive it and stay
 * unchanged); released with hearth_raycaster_free (NULL is fine). Rays are
 * in the mesh's frame and units; a direction need not be a unit vector, t
 * is measured in units of its length (a distance for unit directions). */
hearth_status hearth_raycaster_new(const hearth_mesh *m, hearth_raycaster **out, hearth_err *err);
void hearth_raycaster_free(hearth_raycaster *rc);
/* Nearest hit in (tnear, tfar). Returns 1 on a hit. Thread-safe. */
int hearth_raycast(const hearth_raycaster *rc, const double org[3], const double dir[3],
                   double tnear, double tfar, hearth_ray_hit *hit);
/* Whether the ray meets the mesh anywhere in (tnear, tfar): 1 exactly
 * where hearth_raycast would return 1 (the same triangle test), found
 * without looking for the nearest hit. Thread-safe. */
int hearth_raycast_any(const hearth_raycaster *rc, const double org[3], const double dir[3],
                       double tnear, double tfar);
/* Cast n rays (org/dir 3*n floats) into the caller's hits[n];
 * hits[i].prim = UINT32_MAX where none. */
void hearth_raycast_batch(const hearth_raycaster *rc, size_t n, const float *org, const float *dir,
                          float tnear, float tfar, hearth_ray_hit *hits);
/* The same with an explicit worker count (0 = hearth_default_threads(),
 * 1 = the calling thread only, for callers that are already parallel). */
void hearth_raycast_batch_mt(const hearth_raycaster *rc, size_t n, const float *org,
                             const float *dir, float tnear, float tfar, hearth_ray_hit *hits,
                             int nthreads);

/* ---- a camera's pixel grid cast by rasterisation --------------------------- */
/* The rays through the centres of a camera's pixel grid (every stride-th
 * pixel, lens distortion included), cast at a mesh as a whole: for every
 * pixel, the nearest front-facing triangle along its ray. Back faces never
 * occlude, as with a ray caster that culls them. The front faces are
 * rasterised in the camera's plane z = 1 against the pixels' undistorted
 * centres, with a depth test; for each triangle only the pixels whose
 * centre can lie in it are tested (bounded through the lens model). That is
 * exact, needs no acceleration structure, and costs one pass over the
 * triangles per cast: far cheaper than tracing when the triangles are
 * small. It needs every vertex strictly in front of the camera (z > 0);
 * otherwise cast rays. */
typedef struct hearth_ray_fan hearth_ray_fan;

/* The fan of cam's pixel grid (every stride-th pixel; stride 0 counts as
 * 1); released with hearth_ray_fan_free. */
hearth_status hearth_ray_fan_new(const hearth_camera *cam, size_t stride, hearth_ray_fan **out,
                                 hearth_err *err);
void hearth_ray_fan_free(hearth_ray_fan *f);
/* The grid's unit directions (3 floats per pixel, row-major, w x h): those
 * of hearth_camera_ray_grid, with zero where the lens cannot be inverted
 * (such a pixel never hits). Owned by the fan. */
const float *hearth_ray_fan_dirs(const hearth_ray_fan *f, size_t *w, size_t *h);
/* Bytes of scratch one cast at a mesh of n_vertices needs: one block per
 * concurrent cast, zero-filled before its first cast (calloc); every cast
 * leaves it zero-filled again. The fan itself is only read. */
size_t hearth_ray_fan_scratch_size(const hearth_ray_fan *f, size_t n_vertices);
/* Cast the grid from the pose T_world_from_cam. box = {x0, x1, y0, y1}
 * (grid pixels, inclusive; x0 > x1 when nothing is hit) bounds the hits:
 * hits[p] is written for every grid pixel p in the box only (t along the
 * unit direction, front 1; prim UINT32_MAX where the ray hits nothing), and
 * every pixel outside it hits nothing. Equal depths go to the lower
 * triangle index, so the result depends only on the inputs.
 * HEARTH_E_UNSUPPORTED (naming the vertex) if a vertex is not in front of
 * the camera. */
hearth_status hearth_ray_fan_cast(const hearth_ray_fan *f, const hearth_mesh *m,
                                  const hearth_rigid *T_world_from_cam, void *scratch,
                                  hearth_ray_hit *hits, size_t box[4], hearth_err *err);
/* The same, the hits kept in a frame instead of the grid: the box grown by
 * grow pixels on each side and clipped to the grid, frame = {x0, y0, w, h}
 * (grid pixels; all 0 when nothing is hit). hits[(y - y0) * w + (x - x0)]
 * is written for every pixel of the frame (misses outside the box), so
 * hits needs room for the frame only, at most the grid. */
hearth_status hearth_ray_fan_cast_framed(const hearth_ray_fan *f, const hearth_mesh *m,
                                         const hearth_rigid *T_world_from_cam, void *scratch,
                                         size_t grow, hearth_ray_hit *hits, size_t box[4],
                                         size_t frame[4], hearth_err *err);
/* Without making a fan: a box of the grid pixels (every stride-th pixel of
 * cam) that a cast of m from T_world_from_cam can hit, box = {x0, x1, y0,
 * y1} inclusive (x0 > x1: none). It is the union over every triangle of its
 * vertices' pixels grown by the cast's own bound on the lens's curvature
 * and slack_px (room for the grid's undistortion residual and rounding,
 * e.g. 1), so it holds the hits of any fan of cam's grid, or of any crop of
 * it. HEARTH_E_UNSUPPORTED (naming the vertex) if a vertex is not in front
 * of the camera, or for a lens model other than the fan's 5-parameter one. */
hearth_status hearth_ray_fan_extent(const hearth_camera *cam, size_t stride, const hearth_mesh *m,
                                    const hearth_rigid *T_world_from_cam, double slack_px,
                                    size_t box[4], hearth_err *err);

/* ---- UV islands and texel rasterisation ----------------------------------- */
/* Label connected UV islands: triangles sharing an edge in UV space (same two
 * UV coordinates, bit-exact after welding identical UVs) belong to one
 * island. The caller's island_of_tri[n_triangles] gets 0..n_islands-1. */
hearth_status hearth_uv_islands(const hearth_mesh *m, uint32_t *island_of_tri, uint32_t *n_islands,
                                hearth_err *err);

/* Fold UV islands into [0,1]^2 by whole tiles. With a REPEAT sampler the
 * texture at u + k (k an integer) is the texture at u, so an island lying
 * in one tile [i, i+1] x [j, j+1] (overhanging it by at most
 * HEARTH_UV_TILE_SLACK; [0,1]^2 itself is preferred) is translated by
 * (-i, -j); along a MIRRORED_REPEAT axis an odd tile is reflected instead,
 * u' = i + 1 - u; along a CLAMP_TO_EDGE axis an island outside [0,1] is
 * not moved. Islands here join triangles that share a UV point (bit
 * exact), so a vertex always moves with every triangle using it. wrap:
 * NULL for REPEAT everywhere, or two hearth_uv_wrap codes per triangle (u
 * axis, v axis); an island takes the most restrictive of its triangles'
 * (CLAMP_TO_EDGE over MIRRORED_REPEAT over REPEAT). Islands that cannot be
 * folded (spanning tiles, or clamped) are left as they are and counted.
 * When every UV already lies in [-slack, 1 + slack] nothing is done (all
 * counts 0). */
#define HEARTH_UV_TILE_SLACK 1e-3 /* overhang of an island past its tile, in tiles */
typedef enum hearth_uv_wrap {
  HEARTH_UV_REPEAT = 0,
  HEARTH_UV_MIRRORED_REPEAT = 1,
  HEARTH_UV_CLAMP_TO_EDGE = 2
} hearth_uv_wrap;
typedef struct hearth_uv_tiles {
  uint32_t moved;              /* islands brought into [0,1]^2 */
  uint32_t mirrored;           /* of those, reflected on an axis */
  uint32_t straddling;         /* islands spanning more than one tile: left */
  uint32_t clamped;            /* islands outside [0,1]^2 under CLAMP_TO_EDGE: left */
  size_t triangles_straddling; /* triangles crossing a tile border */
  size_t triangles_left;       /* triangles of the islands left */
  size_t first_left;           /* lowest triangle of an island left; SIZE_MAX if none */
} hearth_uv_tiles;
hearth_status hearth_uv_fold_tiles(hearth_mesh *m, const uint8_t *wrap, hearth_uv_tiles *out,
                                   hearth_err *err);

/* Rasterise the UV layout into R x R (caller's arrays of R * R entries):
 * tri_of_texel[row*R+col] is the triangle whose UV triangle contains the
 * texel centre (UINT32_MAX if none; ties go to the lowest triangle index, so
 * the result is deterministic), bary (optional, 3 floats per texel) its
 * barycentrics. */
hearth_status hearth_uv_rasterize(const hearth_mesh *m, size_t R, uint32_t *tri_of_texel,
                                  float *bary, hearth_err *err);

#ifdef __cplusplus
}
#endif
#endif
