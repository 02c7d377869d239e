// The spillable vertex table: memory blocks, then a temp file or the input read through mmap
// with resident-page accounting (see vertex_table.hpp).
#include "io/vertex_table.hpp"

#include "io/error.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

namespace meshstream::io {
namespace {

constexpr size_t kPageBytes = 4096;
// Residency is accounted in blocks of this size, aligned in the file, not in pages: on a read
// fault in a shared file mapping, Linux maps the page's whole page-cache folio, which can be
// as large as the PMD size (2 MiB on x86-64), and the cached pages within 64 KiB around it
// ("fault-around"), with their folios. Measured on the 6.18 kernel this was written on: one
// byte read from a file the page cache had read ahead made 2 MiB resident, from a file just
// written about 350 KiB.
constexpr uint64_t kResidencyBlockBytes = uint64_t{2} << 20;
constexpr uint64_t kFaultAroundBytes = uint64_t{64} << 10;
constexpr size_t kTailBytes = size_t{1} << 20;

}  // namespace

VertexTable::VertexTable(uint64_t budget_bytes, std::string tmpdir, bool color)
    : budget_bytes_(budget_bytes), tmpdir_(std::move(tmpdir)), color_(color) {
    stride_ = color ? 16 : 12;  // xyz, then rgb + 1 pad byte
}

std::unique_ptr<VertexTable> VertexTable::map_input_file(const std::string& path, uint64_t offset, uint64_t count,
                                                         size_t stride, const size_t (&xyz_offsets)[3],
                                                         const size_t* rgb_offsets, uint64_t budget_bytes) {
    std::unique_ptr<VertexTable> t(new VertexTable());
    t->storage_ = Storage::kInputFile;
    t->budget_bytes_ = budget_bytes;
    t->stride_ = stride;
    t->size_ = count;
    t->mapped_records_ = count;
    std::copy(std::begin(xyz_offsets), std::end(xyz_offsets), t->xyz_offsets_);
    if (rgb_offsets) {
        t->color_ = true;
        std::copy(rgb_offsets, rgb_offsets + 3, t->rgb_offsets_);
    }
    if (count == 0) return t;
    t->input_fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (t->input_fd_ < 0) throw Error(path, "cannot open for mapping: " + std::string(std::strerror(errno)));
    uint64_t aligned = offset / kPageBytes * kPageBytes;
    t->map_bytes_ = static_cast<size_t>(offset - aligned + count * stride);
    t->map_ = ::mmap(nullptr, t->map_bytes_, PROT_READ, MAP_SHARED, t->input_fd_, static_cast<off_t>(aligned));
    if (t->map_ == MAP_FAILED) {
        t->map_ = nullptr;
        throw Error(path, offset, 0, "cannot map the vertex block: " + std::string(std::strerror(errno)));
    }
    t->base_ = static_cast<const std::byte*>(t->map_) + (offset - aligned);
    t->map_file_offset_ = aligned;
    if (t->map_bytes_ > budget_bytes) t->start_accounting();
    return t;
}

VertexTable::~VertexTable() {
    if (map_) ::munmap(map_, map_bytes_);
    if (input_fd_ >= 0) ::close(input_fd_);
}

void VertexTable::append(const float* xyz, const uint8_t* rgb) {
    std::byte rec[16] = {};
    std::memcpy(rec, xyz, 12);
    if (color_ && rgb) std::memcpy(rec + 12, rgb, 3);
    if (storage_ == Storage::kMemory) {
        if ((size_ + 1) * stride_ > budget_bytes_) {
            spill();
        } else {
            size_t in_block = static_cast<size_t>(size_ & ((uint64_t{1} << kBlockRecordsLog2) - 1));
            if (in_block == 0)
                blocks_.push_back(std::make_unique<std::byte[]>(stride_ << kBlockRecordsLog2));
            std::memcpy(blocks_.back().get() + in_block * stride_, rec, stride_);
            ++size_;
            return;
        }
    }
    // kTempFile: append to the tail, flushing it (and extending the mapping) when full.
    if (tail_.size() + stride_ > kTailBytes) flush_tail();
    tail_.insert(tail_.end(), rec, rec + stride_);
    ++size_;
}

void VertexTable::spill() {
    temp_ = std::make_unique<TempFile>(tmpdir_, "meshstream-vertices");
    for (uint64_t done = 0; done < size_;) {
        size_t n = static_cast<size_t>(std::min<uint64_t>(size_ - done, uint64_t{1} << kBlockRecordsLog2));
        temp_->write(blocks_[done >> kBlockRecordsLog2].get(), n * stride_);
        done += n;
    }
    temp_->flush();
    std::vector<std::unique_ptr<std::byte[]>>().swap(blocks_);
    storage_ = Storage::kTempFile;
    tail_.reserve(kTailBytes);
    map_temp(size_ * stride_);
    mapped_records_ = size_;
}

void VertexTable::flush_tail() {
    if (tail_.empty()) return;
    temp_->write(tail_.data(), tail_.size());
    temp_->flush();
    uint64_t records = tail_.size() / stride_;
    tail_.clear();
    uint64_t bytes = (mapped_records_ + records) * stride_;
    if (bytes > map_bytes_) map_temp(bytes);
    mapped_records_ += records;
}

// Maps the temp file with room to grow: a shared mapping longer than the file is valid, and
// the pages become readable as write() extends the file (one page cache).
void VertexTable::map_temp(uint64_t min_bytes) {
    if (map_) ::munmap(map_, map_bytes_);
    map_ = nullptr;
    uint64_t want = std::max<uint64_t>({min_bytes * 2, uint64_t{1} << 30});
    map_bytes_ = static_cast<size_t>(want);
    map_ = ::mmap(nullptr, map_bytes_, PROT_READ, MAP_SHARED, temp_->fd(), 0);
    if (map_ == MAP_FAILED) {
        map_ = nullptr;
        throw Error(temp_->path(), "cannot map the vertex table: " + std::string(std::strerror(errno)));
    }
    base_ = static_cast<const std::byte*>(map_);
    start_accounting();
}

size_t VertexTable::block_count() const {
    return static_cast<size_t>((map_file_offset_ + map_bytes_ + kFaultAroundBytes) / kResidencyBlockBytes + 1);
}

void VertexTable::start_accounting() {
    // At least the three blocks one read can make resident (its own and a neighbour each side).
    block_limit_ = std::max<uint64_t>(budget_bytes_ / kResidencyBlockBytes, 3);
    touched_bits_.assign(block_count() / 64 + 1, 0);
    touched_order_.clear();
}

const std::byte* VertexTable::record_in_map(uint64_t byte_offset) {
    const std::byte* record = base_ + byte_offset;
    if (touched_bits_.empty()) return record;
    // The blocks this read can make resident: the record's (a record of at most 16 bytes may
    // straddle into the next, within the fault-around reach) and those within 64 KiB of it.
    const std::byte* map = static_cast<const std::byte*>(map_);
    const uint64_t at = map_file_offset_ + static_cast<uint64_t>(record - map);
    const uint64_t blocks[3] = {(at > kFaultAroundBytes ? at - kFaultAroundBytes : 0) / kResidencyBlockBytes,
                                at / kResidencyBlockBytes, (at + kFaultAroundBytes) / kResidencyBlockBytes};
    for (const uint64_t block : blocks) {
        uint64_t& word = touched_bits_[block >> 6];
        const uint64_t bit = uint64_t{1} << (block & 63);
        if (!(word & bit)) {
            word |= bit;
            touched_order_.push_back(block);
        }
    }
    // Past the budget, the block touched first goes (first in, first out: faces use vertices
    // near each other, so a sliding window of blocks stays resident). This read's own blocks
    // are the last ones in, and the limit is at least three, so they stay.
    while (touched_order_.size() > block_limit_) {
        const uint64_t block = touched_order_.front();
        touched_order_.pop_front();
        touched_bits_[block >> 6] &= ~(uint64_t{1} << (block & 63));
        // The block's part of the mapping, in file offsets (a block may lie partly or wholly
        // outside it).
        const uint64_t begin = std::max(block * kResidencyBlockBytes, map_file_offset_);
        const uint64_t end = std::min((block + 1) * kResidencyBlockBytes, map_file_offset_ + map_bytes_);
        if (begin < end)
            ::madvise(const_cast<std::byte*>(map + (begin - map_file_offset_)), static_cast<size_t>(end - begin), MADV_DONTNEED);
    }
    return record;
}

void VertexTable::get(uint64_t i, float* xyz, uint8_t* rgb) {
    const std::byte* rec;
    if (storage_ == Storage::kMemory) {
        rec = blocks_[i >> kBlockRecordsLog2].get() + (i & ((uint64_t{1} << kBlockRecordsLog2) - 1)) * stride_;
    } else if (i < mapped_records_) {
        rec = record_in_map(i * stride_);
    } else {
        rec = tail_.data() + (i - mapped_records_) * stride_;
    }
    for (int a = 0; a < 3; ++a) std::memcpy(&xyz[a], rec + xyz_offsets_[a], 4);
    if (rgb) {
        if (color_)
            for (int a = 0; a < 3; ++a) rgb[a] = static_cast<uint8_t>(rec[rgb_offsets_[a]]);
        else
            rgb[0] = rgb[1] = rgb[2] = 0;
    }
}

bool emit_polygon(VertexTable& table, const std::vector<uint64_t>& polygon, PolygonScratch& scratch, size_t* next,
                  TriangleChunk& chunk) {
    const size_t n = polygon.size();
    if (*next + 2 >= n) return true;  // done, or fewer than 3 corners
    if (chunk.full()) return false;
    if (n == 3) {  // most faces: straight into the chunk
        size_t i = chunk.size();
        float* xyz = chunk.push_slot();
        uint8_t* rgb = chunk.rgb_at(i);
        uint64_t* ids = chunk.id_at(i);
        for (int k = 0; k < 3; ++k) {
            table.get(polygon[k], xyz + 3 * k, rgb ? rgb + 3 * k : nullptr);
            if (ids) ids[k] = polygon[k];
        }
        *next = 1;
        return true;
    }
    if (*next == 0) {
        // Each corner is read once, then copied into its triangles.
        scratch.xyz.resize(3 * n);
        scratch.rgb.resize(3 * n);
        for (size_t k = 0; k < n; ++k) table.get(polygon[k], &scratch.xyz[3 * k], &scratch.rgb[3 * k]);
        scratch.triangles.clear();
        triangulate_polygon(scratch.xyz, scratch.triangulate, scratch.triangles);
    }
    for (; *next + 2 < n; ++*next) {
        if (chunk.full()) return false;
        size_t i = chunk.size();
        float* xyz = chunk.push_slot();
        uint8_t* rgb = chunk.rgb_at(i);
        uint64_t* ids = chunk.id_at(i);
        for (int k = 0; k < 3; ++k) {
            const uint32_t corner = scratch.triangles[3 * *next + k];
            std::memcpy(xyz + 3 * k, &scratch.xyz[3 * corner], 3 * sizeof(float));
            if (rgb) std::memcpy(rgb + 3 * k, &scratch.rgb[3 * corner], 3);
            if (ids) ids[k] = polygon[corner];
        }
    }
    return true;
}

}  // namespace meshstream::io
