#pragma once
// the same-surface masks of the shared shadow visibility (realtime_integrator.cc,
// ResolveSharedVisibility): per pixel of a tile, which pixels of its 5x5 window lie on its
// surface (SameShadowSurface, render/light/shadow_window_math.h). SameSurfaceWindows is the scalar
// definition, the transport's ShadowWindowMask (render/transport/realtime_visibility.h) per pixel;
// SameSurfaceWindowsLanes computes the same masks with a tile row's pixels as SIMD
// lanes (AVX-512: 16 pixels per register, one window offset at a time), bit for bit (the same
// float operations per pixel pair, in the shared formula's order; without AVX-512 it is the
// scalar loop).

#include <cstdint>

namespace penumbra {

/// per pixel i of a width x height tile (row-major, width <= 28): bit ShadowWindowBit(dx, dy)
/// set when pixel (x + dx, y + dy) (|dx|, |dy| <= 2, inside the tile) lies on pixel i's surface:
/// geom[i] == geom[j] and SameShadowSurface(geom[i], n_i, p_i, geom[j], n_j, p_j), with its own
/// bit (0, 0) always set; 0 for pixels that did not hit. geom: per pixel, -1 none; p, n: per
/// pixel xyz (hit point and geometric normal, world frame); near: width x height words out.
void SameSurfaceWindows(int width, int height, const bool* did_hit, const int* geom, const float* p,
                        const float* n, uint32_t* near);

/// SameSurfaceWindows with each tile row's pixels as SIMD lanes; the same output, bit for bit.
void SameSurfaceWindowsLanes(int width, int height, const bool* did_hit, const int* geom,
                             const float* p, const float* n, uint32_t* near);

}  // namespace penumbra
