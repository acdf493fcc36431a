// The language layer of the headers shared by the shaders and the C++ (shaders/*.h): each of them
// is valid GLSL 4.50 (included by the shaders like any .glsl file) and valid C++17 with GLM
// (included as "shaders/x.h"), so that a formula the GPU passes and the CPU reference both compute
// is written once. In C++ their contents live in namespace pxf::shared, with GLM's vector types
// and functions in scope, so the shared code reads like the GLSL it also is.
//
// What the shared code may use: GLSL's scalar and vector types and the functions GLM has too;
// no swizzles beyond single components (write vec3(v) for v.rgb), float literals with the f
// suffix (C++ would read 0.5 as a double), and these macros:
//   PXF_CONST         a compile-time constant (const / constexpr)
//   PXF_INLINE        a function (nothing / inline)
//   PXF_OUT(T)        an out parameter (out T / T&)
//   PXF_INOUT(T)      an in-out parameter (inout T / T&)
//   PXF_SAMPLER_FN    a function reading textures: in C++ a template on its sampler2D arguments,
//                     which the caller provides with texelFetch(s, ivec2, 0) and textureSize(s, 0)
//   PXF_FLOAT_ARRAY3(a, b, c), PXF_FLOAT_ARRAY5(...)  the initializer of a const float array
//   PXF_INFINITY      +inf as a float constant
//   wide_float, wide_vec3  the precision of sums and weights: float on the GPU; double in the CPU
//                     reference (it accumulates its kernel sums in double, which makes it an
//                     independent check of the float rounding in the shaders)
#ifdef __cplusplus
#pragma once
#include <limits>
#include <glm/glm.hpp>

#define PXF_CONST constexpr
#define PXF_INLINE inline
#define PXF_OUT(T) T&
#define PXF_INOUT(T) T&
#define PXF_SAMPLER_FN template <class sampler2D>
#define PXF_FLOAT_ARRAY3(a, b, c) {a, b, c}
#define PXF_FLOAT_ARRAY5(a, b, c, d, e) {a, b, c, d, e}
#define PXF_INFINITY std::numeric_limits<float>::infinity()
#define PXF_SHARED_BEGIN namespace pxf::shared { using namespace glm;
#define PXF_SHARED_END }

namespace pxf::shared {
using wide_float = double;
using wide_vec3 = glm::dvec3;
}  // namespace pxf::shared

#else

#define PXF_CONST const
#define PXF_INLINE
#define PXF_OUT(T) out T
#define PXF_INOUT(T) inout T
#define PXF_SAMPLER_FN
#define PXF_FLOAT_ARRAY3(a, b, c) float[3](a, b, c)
#define PXF_FLOAT_ARRAY5(a, b, c, d, e) float[5](a, b, c, d, e)
#define PXF_INFINITY uintBitsToFloat(0x7f800000u)
#define PXF_SHARED_BEGIN
#define PXF_SHARED_END
#define wide_float float
#define wide_vec3 vec3

#endif
