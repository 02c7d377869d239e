// Option validators shared by meshstream and meshstream-gen. CLI11's own parsing of an
// unsigned option takes "-1" as 2^64 - 1 and clamps what is past 2^64 - 1 (strtoull), and its
// Range check lets NaN through: these say what was wrong with the text given.
#pragma once

#include <CLI/CLI.hpp>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>

namespace meshstream::tools {

// A whole number from `min` to 2^64 - 1, in decimal digits only.
inline CLI::Validator whole_number(uint64_t min, const std::string& what) {
    return CLI::Validator(
        [min, what](const std::string& text) -> std::string {
            uint64_t value = 0;
            const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
            if (text.empty() || text[0] == '-' || text[0] == '+' || ec != std::errc() ||
                end != text.data() + text.size() || value < min)
                return "must be " + what + " from " + std::to_string(min) + " to 18446744073709551615, found '" + text +
                       "'";
            return {};
        },
        "N >= " + std::to_string(min));
}

// A number in (0, 1] (CLI::Range would say "Value 0 not in range 0.000000 to 1.000000" for the
// open end).
inline CLI::Validator open_unit_interval() {
    return CLI::Validator(
        [](const std::string& text) -> std::string {
            double value = 0;
            if (!CLI::detail::lexical_cast(text, value) || !(value > 0 && value <= 1))
                return "must be a number in (0, 1], found '" + text + "'";
            return {};
        },
        "in (0, 1]");
}

}  // namespace meshstream::tools
