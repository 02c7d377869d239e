// The words and numbers of every text format meshstream reads (ASCII STL, a PLY's ascii header
// and body, OBJ, MTL): one grammar, so that a token one format reads as a number every other
// reads as the same number, and a token one refuses every other refuses (docs/formats.md,
// *Numbers in text formats*).
//
//   blank    ' ', '\t', '\n', '\r', '\v', '\f'; a word is a run of other bytes
//   number   [sign] (decimal | "inf" | "infinity" | "nan" | "nan(" [A-Za-z0-9_]* ")")
//            with the letters in any case
//   decimal  (digits ["." [digits]] | "." digits) [("e" | "E") [sign] digits]
//   integer  [sign] digits
//   sign     "+" | "-"
//
// The whole word must match: "+-1", "1.2.3", "1e", "0x10", "1,5" and "" are not numbers. A
// decimal past the type's range is ±infinity (1e400) or ±0 (1e-400), as strtod rounds it, so
// it is left to the read loop's non-finite policy like "inf"; an integer past its type's range
// is not one. Reading is std::from_chars (no locale, no allocation), with the sign and the
// range handled here; a number is read straight into float when float is what is kept (no
// double rounding).
#pragma once

#include <charconv>
#include <cstdint>
#include <limits>
#include <string_view>
#include <system_error>
#include <type_traits>

namespace meshstream::io {

inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

// Splits off the next word of `rest` (empty at its end).
inline std::string_view next_word(std::string_view& rest) {
    size_t i = 0;
    while (i < rest.size() && is_blank(rest[i])) ++i;
    size_t j = i;
    while (j < rest.size() && !is_blank(rest[j])) ++j;
    std::string_view w = rest.substr(i, j - i);
    rest.remove_prefix(j);
    return w;
}

// `s` without its leading and trailing blanks.
inline std::string_view trim_blanks(std::string_view s) {
    while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
    return s;
}

namespace detail {

// For a decimal [b, e) (sign included) that std::from_chars found out of range: whether it is
// huge (rounds to infinity) rather than tiny (rounds to zero). Out of range means at least
// ~10^38 or below ~10^-45 (float), so the position of the first significant digit decides.
inline bool decimal_is_huge(const char* b, const char* e) {
    if (b != e && *b == '-') ++b;
    int64_t point = 0;  // where the first significant digit is, as a power of ten (+1)
    bool significant = false;
    for (; b != e && static_cast<unsigned>(*b - '0') < 10; ++b)
        if (significant || *b != '0') significant = true, ++point;
    if (b != e && *b == '.') {
        for (++b; b != e && static_cast<unsigned>(*b - '0') < 10; ++b) {
            if (significant) continue;
            if (*b != '0')
                significant = true;
            else
                --point;
        }
    }
    int64_t exponent = 0;
    if (b != e && (*b == 'e' || *b == 'E')) {
        ++b;
        const bool negative = b != e && *b == '-';
        if (b != e && (*b == '+' || *b == '-')) ++b;
        for (; b != e; ++b)
            if (exponent < 1'000'000'000) exponent = exponent * 10 + (*b - '0');
        if (negative) exponent = -exponent;
    }
    return point + exponent > 0;
}

}  // namespace detail

// Reads the whole of `token` as a number of the grammar above into `out` (float or double);
// false when it is not one (`out` is then unspecified).
template <class F>
bool parse_number(std::string_view token, F& out) {
    static_assert(std::is_floating_point_v<F>);
    const char* b = token.data();
    const char* e = b + token.size();
    if (b != e && *b == '+') {
        ++b;
        if (b != e && *b == '-') return false;  // from_chars would read "-1" of "+-1"
    }
    auto [p, ec] = std::from_chars(b, e, out);
    if (p != e || ec == std::errc::invalid_argument) return false;
    if (ec == std::errc::result_out_of_range) {
        const F magnitude = detail::decimal_is_huge(b, e) ? std::numeric_limits<F>::infinity() : F(0);
        out = *b == '-' ? -magnitude : magnitude;
    }
    return true;
}

// Reads the whole of `token` as an integer of the grammar above into `out`; false when it is
// not one or lies outside T's range (a negative one for an unsigned T).
template <class T>
bool parse_integer(std::string_view token, T& out) {
    static_assert(std::is_integral_v<T> && sizeof(T) <= sizeof(uint64_t));
    const char* b = token.data();
    const char* e = b + token.size();
    const bool negative = b != e && *b == '-';
    if (b != e && (*b == '+' || *b == '-')) ++b;
    if (b == e || static_cast<unsigned>(*b - '0') >= 10) return false;  // one sign, then digits
    uint64_t magnitude = 0;
    auto [p, ec] = std::from_chars(b, e, magnitude);
    if (ec != std::errc() || p != e) return false;
    using U = std::make_unsigned_t<T>;
    if (negative) {
        // The most negative T is -(max + 1); an unsigned T holds no negative value but -0.
        const uint64_t limit = std::is_signed_v<T> ? uint64_t(std::numeric_limits<T>::max()) + 1 : 0;
        if (magnitude > limit) return false;
        out = static_cast<T>(static_cast<U>(0 - magnitude));
    } else {
        if (magnitude > uint64_t(std::numeric_limits<T>::max())) return false;
        out = static_cast<T>(magnitude);
    }
    return true;
}

}  // namespace meshstream::io
