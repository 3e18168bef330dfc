/* Private to the virtual rig: stateless lattice noise for the procedural
 * objects' textures and peel bumps (synth_objects.c) and the temperature
 * fields (synth_fields.c).
 *
 * One lattice: synth_lattice hashes an integer point of a seeded stream to
 * [0,1). Two interpolants over it, because the released bytes depend on both:
 * synth_noise2/3 (cubic fade, nested linear blends; the 2D form is the z = 0
 * slice of the 3D one, bit for bit) for colours and shapes, and
 * synth_smooth_noise3 (quintic fade, C2 smooth) for temperatures.
 * Pure functions: deterministic and thread-safe. Defined here so that the
 * texture loops inline them (out of line, a texture takes ~15 % longer). */
#ifndef HEARTH_SYNTH_NOISE_H
#define HEARTH_SYNTH_NOISE_H

#include <math.h>
#include <stdint.h>

#define SYNTH_NOISE_SALT 7  /* the lattice of synth_noise2/3 */
#define SYNTH_SMOOTH_SALT 3 /* the lattice of synth_smooth_noise3 */

static inline uint64_t synth_mix64(uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

/* Value in [0,1) at lattice point (a, b, c) of stream seed; salt separates
 * lattices that share a seed. */
static inline double synth_lattice(uint64_t seed, uint64_t salt, int64_t a, int64_t b, int64_t c) {
  uint64_t h =
      synth_mix64(seed ^ synth_mix64((uint64_t)a * 0x9E3779B97F4A7C15ULL ^
                                     synth_mix64((uint64_t)b + 0x632BE59BD9B4E019ULL) ^
                                     synth_mix64((uint64_t)c * 0xD6E8FEB86659FD93ULL + salt)));
  return (double)(h >> 11) * (1.0 / 9007199254740992.0);
}

static inline double synth_fade3(double t) { return t * t * (3.0 - 2.0 * t); }

/* bilinear blend over cell (ix, iy) of the lattice layer z = iz */
static inline double synth_noise_layer(uint64_t seed, int64_t ix, int64_t iy, int64_t iz, double tx,
                                       double ty) {
  double a = synth_lattice(seed, SYNTH_NOISE_SALT, ix, iy, iz);
  double b = synth_lattice(seed, SYNTH_NOISE_SALT, ix + 1, iy, iz);
  double c = synth_lattice(seed, SYNTH_NOISE_SALT, ix, iy + 1, iz);
  double d = synth_lattice(seed, SYNTH_NOISE_SALT, ix + 1, iy + 1, iz);
  double ab = a + (b - a) * tx, cd = c + (d - c) * tx;
  return ab + (cd - ab) * ty;
}

/* Value noise in [-1, 1]: cubic fade over lattice SYNTH_NOISE_SALT. */
static inline double synth_noise3(uint64_t seed, double x, double y, double z) {
  double fx = floor(x), fy = floor(y), fz = floor(z);
  int64_t ix = (int64_t)fx, iy = (int64_t)fy, iz = (int64_t)fz;
  double tx = synth_fade3(x - fx), ty = synth_fade3(y - fy), tz = synth_fade3(z - fz);
  double v0 = synth_noise_layer(seed, ix, iy, iz, tx, ty);
  double v1 = synth_noise_layer(seed, ix, iy, iz + 1, tx, ty);
  return 2.0 * (v0 + (v1 - v0) * tz) - 1.0;
}

/* synth_noise3(seed, x, y, 0) without the layer that has no weight there */
static inline double synth_noise2(uint64_t seed, double x, double y) {
  double fx = floor(x), fy = floor(y);
  double tx = synth_fade3(x - fx), ty = synth_fade3(y - fy);
  return 2.0 * synth_noise_layer(seed, (int64_t)fx, (int64_t)fy, 0, tx, ty) - 1.0;
}

/* Octaves of synth_noise2 (frequency x2.03, amplitude x0.5 each), in [-1, 1]. */
static inline double synth_fbm2(uint64_t seed, double x, double y, int octaves) {
  double s = 0, amp = 0.5, norm = 0;
  for (int o = 0; o < octaves; o++) {
    s += amp * synth_noise2(seed + (uint64_t)o * 101, x, y);
    norm += amp;
    x *= 2.03;
    y *= 2.03;
    amp *= 0.5;
  }
  return s / norm;
}

/* Value noise in [-1, 1]: quintic fade (C2), corner values in [-1, 1) from
 * lattice SYNTH_SMOOTH_SALT, summed with their trilinear weights. */
static inline double synth_smooth_noise3(uint64_t seed, double x, double y, double z) {
  double fx = floor(x), fy = floor(y), fz = floor(z);
  int64_t ix = (int64_t)fx, iy = (int64_t)fy, iz = (int64_t)fz;
  double u[3] = {x - fx, y - fy, z - fz};
  for (int k = 0; k < 3; k++) u[k] = u[k] * u[k] * u[k] * (u[k] * (u[k] * 6 - 15) + 10);
  double v = 0;
  for (int c = 0; c < 8; c++) {
    double w =
        ((c & 1) ? u[0] : 1 - u[0]) * ((c & 2) ? u[1] : 1 - u[1]) * ((c & 4) ? u[2] : 1 - u[2]);
    double corner = synth_lattice(seed, SYNTH_SMOOTH_SALT, ix + (c & 1), iy + ((c >> 1) & 1),
                                  iz + ((c >> 2) & 1));
    v += w * (2.0 * corner - 1.0);
  }
  return v;
}

#endif
