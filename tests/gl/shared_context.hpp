#pragma once
// The GL tests' context: one headless context per test process, made current again at the
// start of each test case (a test may have made another context current, or none).
#include <bounce/gl/context.hpp>

namespace bounce::gl_test {

inline gl::context& shared_context() {
    static gl::context c;
    c.make_current();
    return c;
}

}  // namespace bounce::gl_test
