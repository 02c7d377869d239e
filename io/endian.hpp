// Byte order for the binary formats: loads and stores of little-endian values whatever the
// host (binary STL, binary PLY, meshstream's triangle stream), and the byte swap for
// big-endian PLY. On a little-endian host the array forms are one memcpy. ByteWriter and
// ByteReader put and get a record's fields one after another (part files, MPI messages).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
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

// Appends fields to a byte string: numbers in little-endian order, texts as a u32 length and
// their bytes, and whole trivially copyable structs as their bytes (native layout: for records
// read back by the same build only).
class ByteWriter {
public:
    template <class T>
    void value(T v) {
        static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>);
        if constexpr (std::is_enum_v<T>)
            value(static_cast<std::underlying_type_t<T>>(v));
        else
            append_le(bytes_, v);
    }
    void text(const std::string& s) {
        value(uint32_t(s.size()));
        raw_bytes(s.data(), s.size());
    }
    template <class T>
    void raw(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        raw_bytes(&v, sizeof v);
    }
    void raw_bytes(const void* data, size_t n) {
        if (n == 0) return;
        const size_t at = bytes_.size();
        bytes_.resize(at + n);
        std::memcpy(bytes_.data() + at, data, n);
    }
    const std::vector<std::byte>& bytes() const { return bytes_; }
    const std::byte* data() const { return bytes_.data(); }
    size_t size() const { return bytes_.size(); }
    void clear() { bytes_.clear(); }

private:
    std::vector<std::byte> bytes_;
};

// Reads what ByteWriter wrote, in the same order. Past the end nothing is read: the value is
// T{} and ok() turns false for good, so a reader checks once after a group of fields.
class ByteReader {
public:
    ByteReader(const void* data, size_t n) : p_(static_cast<const std::byte*>(data)), n_(n) {}
    template <class T>
    T value() {
        static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>);
        if constexpr (std::is_enum_v<T>) {
            return static_cast<T>(value<std::underlying_type_t<T>>());
        } else {
            if (!take(sizeof(T))) return T{};
            return load_le<T>(p_ + at_ - sizeof(T));
        }
    }
    std::string text() {
        const auto n = value<uint32_t>();
        if (!take(n)) return {};
        return std::string(reinterpret_cast<const char*>(p_ + at_ - n), n);
    }
    template <class T>
    T raw() {
        static_assert(std::is_trivially_copyable_v<T>);
        T v{};
        if (take(sizeof v)) std::memcpy(&v, p_ + at_ - sizeof v, sizeof v);
        return v;
    }
    bool ok() const { return ok_; }
    // Bytes read so far, and left.
    size_t offset() const { return at_; }
    size_t left() const { return n_ - at_; }
    // Marks the record bad (a field out of its range).
    void fail() { ok_ = false; }

private:
    bool take(size_t n) {
        if (!ok_ || n > n_ - at_) {
            ok_ = false;
            return false;
        }
        at_ += n;
        return true;
    }
    const std::byte* p_;
    size_t n_, at_ = 0;
    bool ok_ = true;
};

}  // namespace meshstream::io
