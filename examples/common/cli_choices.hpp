#pragma once
/// \file cli_choices.hpp
/// Options whose value is one of a few names (--backend cpu | gl, --visibility stereo |
/// hemicube | rays ...), read into the program's enum when the command line is parsed: the
/// programs compare enums, never strings, and print a value's name (reports, summaries)
/// from the same table the command line reads.
///
/// CLI::CheckedTransformer would do the mapping too, but it also takes an enum's number ("1"
/// for gl) and changes the help and the refusal; add_choice keeps those of CLI::IsMember on a
/// string option: "TEXT:{cpu,gl}" in the help, "vulkan not in {cpu,gl}" when refused.

#include <bounce/errors.hpp>

#include <CLI/CLI.hpp>

#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace bounce::examples {

/// The names an option takes, each with the value it stands for, in the order help lists them.
template <class E>
using choices = std::vector<std::pair<std::string, E>>;

/// The name `names` gives `value`: the spelling the command line takes.
template <class E>
const std::string& name_of(const choices<E>& names, E value) {
    for (const auto& [name, v] : names)
        if (v == value) return name;
    throw std::logic_error("a value the option's names do not list");
}

/// Declares `flag`, which reads one of `names` into `value`. Its default (with
/// ->capture_default_str()) is printed by name.
template <class E>
CLI::Option* add_choice(CLI::App& app, const std::string& flag, E& value, const choices<E>& names,
                        const std::string& help) {
    static_assert(std::is_enum_v<E>);
    std::string set = "{";
    for (const auto& [name, v] : names) set += (set.size() > 1 ? "," : "") + name;
    set += "}";
    // CLI11 reads an enum option as its underlying number: the name becomes that number.
    const CLI::Validator to_value(
        [names, set](std::string& input) -> std::string {
            for (const auto& [name, v] : names)
                if (name == input) {
                    input = std::to_string(static_cast<long long>(static_cast<std::underlying_type_t<E>>(v)));
                    return {};
                }
            return input + " not in " + set;
        },
        set);
    return app.add_option(flag, value, help)
        ->type_name("TEXT")
        ->transform(to_value)
        ->default_function([&value, names] { return name_of(names, value); });
}

/// The programs' two backends (--backend cpu | gl).
enum class backend { cpu, gl };
inline const choices<backend> backend_names{{"cpu", backend::cpu}, {"gl", backend::gl}};

/// Refuses --backend gl in a build without the GL adapter (BOUNCE_WITH_GL, which linking
/// bounce::gl defines), before any work.
inline void check_backend_built([[maybe_unused]] backend b) {
#ifndef BOUNCE_WITH_GL
    if (b == backend::gl) throw parameter_error("--backend", "'gl': this build has no GL adapter; use --backend cpu");
#endif
}

}  // namespace bounce::examples
