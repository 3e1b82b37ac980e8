#pragma once
// The one RGBA32F colour target of a framebuffer that a pass draws into, made again only when
// the size changes. Plumbing only.
#include <bounce/gl/objects.hpp>

#include <cstddef>
#include <optional>

namespace bounce::gl::detail {

/// Makes `target` a width x height RGBA32F texture attached to `fbo` as its only colour
/// target, unless it already is one of that size.
inline void ensure_color_target(std::optional<texture>& target, framebuffer& fbo, std::size_t width, std::size_t height) {
    if (target && target->width() == width && target->height() == height) return;
    target.emplace(texel_format::rgba32f, width, height);
    fbo.attach_color(0, *target);
    fbo.set_draw_buffers(1);
    fbo.check_complete();
}

}  // namespace bounce::gl::detail
