// The core alone: Ward's weight (Gautron 2008, Eq. 8.2) from the installed headers, on plain
// glm vectors. Exits non-zero if the value is wrong.
#include <bounce/cache/weighting.hpp>

#include <cmath>
#include <cstdio>

int main() {
    const glm::vec3 n(0, 0, 1);
    // Half a radius away with the same normal: 1 / (0.5 / 1 + 0) = 2.
    const float w = 1.f / bounce::ward_weight::inverse_weight(glm::vec3(0.5f, 0, 0), n, glm::vec3(0.f), n, 1.f);
    std::printf("Ward's weight at half a radius: %g\n", double(w));
    return std::abs(w - 2.f) < 1e-6f ? 0 : 1;
}
