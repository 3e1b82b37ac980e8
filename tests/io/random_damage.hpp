#pragma once
// Random damage to a file's bytes for the loaders' "nothing but scene_error" tests: 1 to 4
// edits, each a random byte, a cut, an inserted token, a truncation or a repeated run.
#include <bounce/sampling.hpp>

#include <string>
#include <vector>

namespace bounce::test {

inline std::string damage(std::string text, pcg32& rng, const std::vector<std::string>& tokens) {
    const int edits = 1 + int(rng.next_u32() % 4);
    for (int e = 0; e < edits && !text.empty(); ++e) {
        const std::size_t pos = rng.next_u32() % text.size();
        switch (rng.next_u32() % 5) {
            case 0: text[pos] = char(rng.next_u32() & 0xff); break;
            case 1: text.erase(pos, 1 + rng.next_u32() % 8); break;
            case 2: text.insert(pos, tokens[rng.next_u32() % tokens.size()]); break;
            case 3: text.resize(pos); break;
            default: text.insert(pos, text.substr(pos, 1 + rng.next_u32() % 16)); break;
        }
    }
    return text;
}

}  // namespace bounce::test
