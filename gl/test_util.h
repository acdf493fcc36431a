// Test helpers of gl_tests: one shared OSMesa context (made current by each test).
#pragma once
#include <gtest/gtest.h>
#include <memory>
#include "gl/context.h"

namespace pxf::test {

// The blend threshold t the pass tests give the filter's case-2 skip where the test is not about t
// (the production value is PreviewSettings::threshold, preview/preview.h).
constexpr float kTestThreshold = 0.01f;

inline GlContext& osmesa_context() {
  static std::unique_ptr<GlContext> context = create_gl_context(GlBackend::OSMesa);
  context->make_current();
  return *context;
}

}  // namespace pxf::test
