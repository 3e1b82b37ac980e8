#pragma once
/// \file image.hpp
/// `image<T>` owns pixels; `image_view<T>` borrows them (width, height, row stride).
///
/// Every backend reads and writes views, and a renderer wraps its own memory in a view
/// without copying. Pixels are row-major, row 0 at the top, pixel (x, y) at
/// `data[y * stride + x]`; the stride counts elements, not bytes, and is at least `width`.

#include <bounce/errors.hpp>

#include <cmath>
#include <cstddef>
#include <span>
#include <type_traits>
#include <vector>

namespace bounce {

template <class T>
class image_view {
public:
    using value_type = std::remove_const_t<T>;

    constexpr image_view() noexcept = default;
    /// Borrows `width` x `height` pixels at `data`, rows `stride` elements apart
    /// (0 means tightly packed). Throws `parameter_error` on a stride below the width
    /// or a null pointer with a non-empty size.
    image_view(T* data, std::size_t width, std::size_t height, std::size_t stride = 0)
        : data_(data), width_(width), height_(height), stride_(stride ? stride : width) {
        require(stride_ >= width_, "stride", "row stride is smaller than the width");
        require(data_ != nullptr || width_ * height_ == 0, "data", "null pointer for a non-empty image");
    }
    /// A view of mutable pixels converts to a view of const pixels.
    template <class U>
        requires(std::is_const_v<T> && std::same_as<std::remove_const_t<T>, U>)
    constexpr image_view(const image_view<U>& o) noexcept
        : data_(o.data()), width_(o.width()), height_(o.height()), stride_(o.stride()) {}

    constexpr std::size_t width() const noexcept { return width_; }
    constexpr std::size_t height() const noexcept { return height_; }
    constexpr std::size_t stride() const noexcept { return stride_; }
    constexpr bool empty() const noexcept { return width_ == 0 || height_ == 0; }
    constexpr T* data() const noexcept { return data_; }

    constexpr T& operator()(std::size_t x, std::size_t y) const noexcept { return data_[y * stride_ + x]; }
    /// Row `y` as a span of `width` pixels.
    constexpr std::span<T> row(std::size_t y) const noexcept { return {data_ + y * stride_, width_}; }

    /// The rectangle [x0, x0+w) x [y0, y0+h) as a view of the same memory.
    image_view subview(std::size_t x0, std::size_t y0, std::size_t w, std::size_t h) const {
        require(x0 + w <= width_ && y0 + h <= height_, "subview", "rectangle outside the image");
        return image_view(data_ + y0 * stride_ + x0, w, h, stride_);
    }

private:
    T* data_ = nullptr;
    std::size_t width_ = 0, height_ = 0, stride_ = 0;
};

/// An owning, tightly packed image.
template <class T>
class image {
public:
    image() = default;
    /// `width` x `height` pixels set to `fill`. Both sizes must be positive.
    image(std::size_t width, std::size_t height, const T& fill = T{})
        : width_(width), height_(height) {
        require(width > 0 && height > 0, "width/height", "image size must be positive");
        pixels_.assign(width * height, fill);
    }

    std::size_t width() const noexcept { return width_; }
    std::size_t height() const noexcept { return height_; }
    bool empty() const noexcept { return pixels_.empty(); }
    T* data() noexcept { return pixels_.data(); }
    const T* data() const noexcept { return pixels_.data(); }
    T& operator()(std::size_t x, std::size_t y) noexcept { return pixels_[y * width_ + x]; }
    const T& operator()(std::size_t x, std::size_t y) const noexcept { return pixels_[y * width_ + x]; }

    image_view<T> view() noexcept { return {pixels_.data(), width_, height_}; }
    image_view<const T> view() const noexcept { return {pixels_.data(), width_, height_}; }
    operator image_view<T>() noexcept { return view(); }
    operator image_view<const T>() const noexcept { return view(); }

private:
    std::size_t width_ = 0, height_ = 0;
    std::vector<T> pixels_;
};

/// Throws `parameter_error` naming `name` at the first pixel with a NaN or infinite
/// component. `T` is a float, a double or a GLM vector of them.
template <class T>
void require_finite(image_view<const T> img, const char* name) {
    for (std::size_t y = 0; y < img.height(); ++y)
        for (std::size_t x = 0; x < img.width(); ++x) {
            const auto& p = img(x, y);
            bool ok = true;
            if constexpr (std::is_floating_point_v<T>) ok = std::isfinite(p);
            else
                for (int c = 0; c < T::length(); ++c) ok = ok && std::isfinite(p[c]);
            if (!ok)
                throw parameter_error(name, "non-finite value at pixel (" + std::to_string(x) + ", " +
                                                std::to_string(y) + ")");
        }
}

}  // namespace bounce
