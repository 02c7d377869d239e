// Byte order for the binary formats: loads and stores of little-endian values whatever the
// host (binary STL, binary PLY, meshstream's triangle stream), and the byte swap for
// big-endian PLY. On a little-endian host the array forms are one memcpy.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

namespace meshstream::io {

// The unsigned integer type of T's size (T: an arithmetic type of 1, 2, 4 or 8 bytes).
template <class T>
using BitsOf = std::conditional_t<
    sizeof(T) == 8, uint64_t,
    std::conditional_t<sizeof(T) == 4, uint32_t, std::conditional_t<sizeof(T) == 2, uint16_t, uint8_t>>>;

// T with its bytes reversed.
template <class T>
T byteswap(T value) {
    using U = BitsOf<T>;
    U bits = std::bit_cast<U>(value);
    if constexpr (sizeof(T) == 2) bits = __builtin_bswap16(bits);
    if constexpr (sizeof(T) == 4) bits = __builtin_bswap32(bits);
    if constexpr (sizeof(T) == 8) bits = __builtin_bswap64(bits);
    return std::bit_cast<T>(bits);
}

// The little-endian T at p (any alignment).
template <class T>
T load_le(const void* p) {
    const auto* b = static_cast<const unsigned char*>(p);
    using U = BitsOf<T>;
    U bits = 0;
    for (size_t i = 0; i < sizeof(T); ++i) bits |= static_cast<U>(static_cast<U>(b[i]) << (8 * i));
    return std::bit_cast<T>(bits);
}

// Stores value at p in little-endian order (any alignment).
template <class T>
void store_le(void* p, T value) {
    auto* b = static_cast<unsigned char*>(p);
    const BitsOf<T> bits = std::bit_cast<BitsOf<T>>(value);
    for (size_t i = 0; i < sizeof(T); ++i) b[i] = static_cast<unsigned char>(bits >> (8 * i));
}

// Appends value in little-endian order.
template <class T>
void append_le(std::vector<std::byte>& out, T value) {
    const BitsOf<T> bits = std::bit_cast<BitsOf<T>>(value);
    for (size_t i = 0; i < sizeof(T); ++i) out.push_back(static_cast<std::byte>(bits >> (8 * i)));
}

// Copies n little-endian values from src to dst; returns the byte after the last one read.
template <class T>
const std::byte* load_le_array(const std::byte* src, T* dst, size_t n) {
    if constexpr (std::endian::native == std::endian::little) {
        std::memcpy(dst, src, n * sizeof(T));
    } else {
        for (size_t i = 0; i < n; ++i) dst[i] = load_le<T>(src + i * sizeof(T));
    }
    return src + n * sizeof(T);
}

// Stores n values from src at dst in little-endian order; returns the byte after the last one.
template <class T>
std::byte* store_le_array(std::byte* dst, const T* src, size_t n) {
    if constexpr (std::endian::native == std::endian::little) {
        std::memcpy(dst, src, n * sizeof(T));
    } else {
        for (size_t i = 0; i < n; ++i) store_le(dst + i * sizeof(T), src[i]);
    }
    return dst + n * sizeof(T);
}

}  // namespace meshstream::io
