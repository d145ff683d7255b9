#include "fieldrig/core/frame_pool.h"

#include <fmt/format.h>

#include <limits>
#include <new>
#include <utility>

namespace fieldrig::core {

Result<std::unique_ptr<FramePool>> FramePool::create(std::size_t buffer_count,
                                                     std::size_t buffer_bytes) {
  if (buffer_count == 0)
    return Error{"frame pool: the buffer count must be positive"};
  if (buffer_bytes == 0)
    return Error{"frame pool: the buffer size must be positive"};
  if (buffer_count > kMaxBuffers) {
    return Error{
        fmt::format("frame pool: {} buffers requested, at most {} (Boost.Lockfree's limit)",
                    buffer_count, kMaxBuffers)};
  }
  if (buffer_bytes > std::numeric_limits<std::size_t>::max() / buffer_count) {
    return Error{fmt::format("frame pool: {} buffers of {} bytes overflow the addressable size",
                             buffer_count, buffer_bytes)};
  }
  // Allocation is the one failure left, and a pool is sized from configuration: report it. The
  // buffers are asked for without throwing: AddressSanitizer (scripts/test-sanitize.sh) aborts on
  // a throwing new it cannot satisfy, but lets a non-throwing one return null as glibc does.
  const auto fail = [&] {
    return Error{fmt::format("frame pool: cannot allocate {} buffers of {} bytes ({} bytes in all)",
                             buffer_count, buffer_bytes, buffer_count * buffer_bytes)};
  };
  std::unique_ptr<std::uint8_t[]> memory(new (std::nothrow)
                                             std::uint8_t[buffer_count * buffer_bytes]());
  if (!memory)
    return fail();
  try {
    return std::unique_ptr<FramePool>(new FramePool(buffer_count, buffer_bytes, std::move(memory)));
  } catch (const std::bad_alloc&) {
    return fail();
  }
}

FramePool::FramePool(std::size_t buffer_count, std::size_t buffer_bytes,
                     std::unique_ptr<std::uint8_t[]> memory)
    : buffer_count_(buffer_count),
      buffer_bytes_(buffer_bytes),
      memory_(std::move(memory)),
      references_(std::make_unique<std::atomic<int>[]>(buffer_count)),
      free_(buffer_count),
      available_(buffer_count) {
  for (std::size_t i = 0; i < buffer_count; ++i) {
    references_[i].store(0, std::memory_order_relaxed);
    free_.bounded_push(static_cast<std::uint32_t>(i));
  }
}

FramePool::~FramePool() = default;

FrameBuffer FramePool::acquire() {
  std::uint32_t index = 0;
  if (!free_.pop(index))
    return {};
  available_.fetch_sub(1, std::memory_order_relaxed);
  references_[index].store(1, std::memory_order_relaxed);
  return FrameBuffer(this, index);
}

void FramePool::addReference(std::uint32_t index) noexcept {
  references_[index].fetch_add(1, std::memory_order_relaxed);
}

void FramePool::dropReference(std::uint32_t index) noexcept {
  // acq_rel: the last holder's writes to the pixels happen-before the next acquirer's.
  if (references_[index].fetch_sub(1, std::memory_order_acq_rel) == 1) {
    available_.fetch_add(1, std::memory_order_relaxed);
    free_.bounded_push(index);  // cannot fail: the queue holds every index at most once
  }
}

FrameBuffer::FrameBuffer(const FrameBuffer& other) noexcept
    : pool_(other.pool_), index_(other.index_) {
  if (pool_)
    pool_->addReference(index_);
}

FrameBuffer::FrameBuffer(FrameBuffer&& other) noexcept
    : pool_(std::exchange(other.pool_, nullptr)), index_(other.index_) {}

FrameBuffer& FrameBuffer::operator=(const FrameBuffer& other) noexcept {
  if (this != &other) {
    FrameBuffer copy(other);
    *this = std::move(copy);
  }
  return *this;
}

FrameBuffer& FrameBuffer::operator=(FrameBuffer&& other) noexcept {
  if (this != &other) {
    reset();
    pool_ = std::exchange(other.pool_, nullptr);
    index_ = other.index_;
  }
  return *this;
}

FrameBuffer::~FrameBuffer() {
  reset();
}

void FrameBuffer::reset() noexcept {
  if (pool_)
    std::exchange(pool_, nullptr)->dropReference(index_);
}

std::span<std::uint8_t> FrameBuffer::bytes() const {
  if (!pool_)
    return {};
  return {pool_->data(index_), pool_->bufferBytes()};
}

std::size_t FrameBuffer::size() const {
  return pool_ ? pool_->bufferBytes() : 0;
}

int FrameBuffer::useCount() const {
  return pool_ ? pool_->references_[index_].load(std::memory_order_relaxed) : 0;
}

}  // namespace fieldrig::core
