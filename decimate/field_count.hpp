// The number of fields of an aggregate of scalars, counted by brace initialization: T{a, b, …}
// with n values that convert to anything compiles exactly when T has at least n fields (scalar
// fields take no brace elision, which would let one field take several values).
#pragma once

#include <cstddef>
#include <type_traits>
#include <utility>

namespace meshstream::decimate {
namespace field_count_detail {

struct AnyField {
    template <typename T>
    constexpr operator T() const {
        return T{};
    }
};

template <typename T, size_t... I>
constexpr bool initializable_with(std::index_sequence<I...>) {
    return requires { T{(void(I), AnyField{})...}; };
}

}  // namespace field_count_detail

template <typename T, size_t n = 0>
constexpr size_t field_count() {
    static_assert(std::is_aggregate_v<T>);
    if constexpr (field_count_detail::initializable_with<T>(std::make_index_sequence<n + 1>{}))
        return field_count<T, n + 1>();
    else
        return n;
}

}  // namespace meshstream::decimate
