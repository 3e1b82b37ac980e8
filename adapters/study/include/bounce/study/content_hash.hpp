#pragma once
/// \file content_hash.hpp
/// FNV-1a, 64 bit, over the bytes of values: a stable, dependency-free content hash for
/// cache keys, which only have to change when their inputs do. It is not a security
/// boundary, and it reads values in the host's byte order.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>

namespace bounce::study {

class fnv1a_hash {
public:
    static constexpr std::uint64_t offset_basis = 0xcbf29ce484222325ULL;
    static constexpr std::uint64_t prime = 0x100000001b3ULL;

    void bytes(const void* data, std::size_t n) noexcept {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * prime;
    }
    /// The object representation of `v` (for types without padding, such as glm vectors).
    template <class T>
        requires std::is_trivially_copyable_v<T>
    void value(const T& v) noexcept {
        bytes(&v, sizeof(T));
    }
    /// value() of each of `v`, in order.
    template <class... T>
    void values(const T&... v) noexcept {
        (value(v), ...);
    }
    /// The length, then the characters, so that ("ab", "c") and ("a", "bc") differ.
    void text(std::string_view s) noexcept {
        value(s.size());
        bytes(s.data(), s.size());
    }
    std::uint64_t digest() const noexcept { return h_; }
    /// digest() as 16 lower-case hex digits, the tail of every cache key.
    std::string hex_digest() const {
        static constexpr char digits[] = "0123456789abcdef";
        std::string out(16, '0');
        for (int i = 0; i < 16; ++i) out[std::size_t(15 - i)] = digits[(h_ >> (4 * i)) & 0xf];
        return out;
    }

private:
    std::uint64_t h_ = offset_basis;
};

}  // namespace bounce::study
