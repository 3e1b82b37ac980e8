// The Cornell box as an io::scene: the core's box (bounce/cornell_box.hpp, the published
// data of the Cornell University Program of Computer Graphics) with its name.
#include <bounce/cornell_box.hpp>
#include <bounce/io/scene.hpp>

namespace bounce::io {

scene cornell_box() {
    scene s;
    s.name = "cornell";
    build_cornell_box(s);
    return s;
}

}  // namespace bounce::io
