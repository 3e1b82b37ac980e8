// The content hash behind the caches' keys: FNV-1a as published.
#include <bounce/study/content_hash.hpp>

#include <catch2/catch.hpp>

#include <cstdint>
#include <cstdio>
#include <string_view>

TEST_CASE("fnv1a_hash gives FNV-1a's published 64-bit values, and text() keeps its pieces apart", "[study][hash]") {
    // Vectors of the FNV reference (Fowler, Noll, Vo): "", "a", "foobar".
    const auto of = [](std::string_view s) {
        bounce::study::fnv1a_hash h;
        h.bytes(s.data(), s.size());
        return h.digest();
    };
    CHECK(of("") == 0xcbf29ce484222325ULL);
    CHECK(of("a") == 0xaf63dc4c8601ec8cULL);
    CHECK(of("foobar") == 0x85944171f73967e8ULL);
    // Hashing in pieces is hashing the concatenation; value() reads the object's bytes.
    bounce::study::fnv1a_hash pieces;
    pieces.bytes("foo", 3);
    pieces.bytes("bar", 3);
    CHECK(pieces.digest() == of("foobar"));
    const std::uint32_t word = 0x61626364u;  // "dcba" in little-endian memory
    bounce::study::fnv1a_hash w;
    w.value(word);
    bounce::study::fnv1a_hash raw;
    raw.bytes(&word, sizeof word);
    CHECK(w.digest() == raw.digest());
    // text() prefixes the length: ("ab", "c") and ("a", "bc") differ though their bytes agree.
    bounce::study::fnv1a_hash ab_c, a_bc;
    ab_c.text("ab");
    ab_c.text("c");
    a_bc.text("a");
    a_bc.text("bc");
    CHECK(ab_c.digest() != a_bc.digest());
}

TEST_CASE("hex_digest spells the digest as the cache keys always did: 16 lower-case hex digits", "[study][hash]") {
    for (const char* text : {"", "a", "bounce-reference-1", "a longer text with spaces"}) {
        bounce::study::fnv1a_hash h;
        h.text(text);
        char expected[17];
        std::snprintf(expected, sizeof expected, "%016llx", static_cast<unsigned long long>(h.digest()));
        CHECK(h.hex_digest() == expected);
    }
}
