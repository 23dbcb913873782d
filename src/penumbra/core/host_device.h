#pragma once
// PB_HOST_DEVICE marks a function that both processors run: the CPU backend and the CUDA
// backend call the same definition, so a shading formula is written once (as
// pbrt-v4's PBRT_CPU_GPU, Pharr, Jakob and Humphreys, "Physically Based Rendering", 4th ed.,
// section 1.7). compiled by nvcc (or clang in CUDA mode, both define __CUDACC__) it is
// `__host__ __device__`; in plain C++ it is empty and such a function is an ordinary one.
//
//   PB_HOST_DEVICE inline float Luminance(float r, float g, float b) { ... }
//
// a PB_HOST_DEVICE function may only call other PB_HOST_DEVICE (or constexpr) functions and
// must not throw, allocate or touch the standard library's containers: device code has none.

#if defined(__CUDACC__)
#define PB_HOST_DEVICE __host__ __device__
#else
#define PB_HOST_DEVICE
#endif

// a * b, a + b and a - b, each rounded once to float on both processors: on the device
// __fmul_rn, __fadd_rn and __fsub_rn, which nvcc never contracts into a fused multiply-add (it
// contracts a * b + c by default; the host compiles with -ffp-contract=off), for the code whose
// GPU results must be the CPU's bits (the realtime splat's ray-capsule test in
// render/particles/particle_math.h: a grazing ray must meet the capsule on both or on neither).
PB_HOST_DEVICE inline float MulRn(float a, float b) {
#if defined(__CUDA_ARCH__)
  return __fmul_rn(a, b);
#else
  return a * b;
#endif
}
PB_HOST_DEVICE inline float AddRn(float a, float b) {
#if defined(__CUDA_ARCH__)
  return __fadd_rn(a, b);
#else
  return a + b;
#endif
}
// the same for doubles (the realtime splat's rays of a moving camera: Camera::GenerateRay's
// double product).
PB_HOST_DEVICE inline double MulRnD(double a, double b) {
#if defined(__CUDA_ARCH__)
  return __dmul_rn(a, b);
#else
  return a * b;
#endif
}
PB_HOST_DEVICE inline double AddRnD(double a, double b) {
#if defined(__CUDA_ARCH__)
  return __dadd_rn(a, b);
#else
  return a + b;
#endif
}
PB_HOST_DEVICE inline float SubRn(float a, float b) {
#if defined(__CUDA_ARCH__)
  return __fsub_rn(a, b);
#else
  return a - b;
#endif
}
