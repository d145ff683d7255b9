// Frame buffers allocated once at start, borrowed by frames, recycled when the last user lets go.
//
// A FramePool owns N equally sized pixel buffers. acquire() hands out a FrameBuffer: a counted
// reference to one buffer. Copies share the buffer (the recorder and the live pipeline both hold
// a FrameSet); when the last copy is destroyed the buffer returns to the pool. Nothing is
// allocated after create(), and acquire() never blocks: an exhausted pool returns an empty
// FrameBuffer and the caller counts a drop (STYLE.md items 3 and 5).
//
// Thread-safe: acquire() and FrameBuffer copies/destruction may happen on any threads. The pool
// must outlive every FrameBuffer taken from it.
#pragma once

#include <atomic>
#include <boost/lockfree/queue.hpp>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

#include "fieldrig/core/result.h"

namespace fieldrig::core {

class FramePool;

class FrameBuffer {
 public:
  FrameBuffer() = default;
  FrameBuffer(const FrameBuffer& other) noexcept;
  FrameBuffer(FrameBuffer&& other) noexcept;
  FrameBuffer& operator=(const FrameBuffer& other) noexcept;
  FrameBuffer& operator=(FrameBuffer&& other) noexcept;
  ~FrameBuffer();

  explicit operator bool() const { return pool_ != nullptr; }
  std::span<std::uint8_t> bytes() const;
  std::size_t size() const;
  // How many FrameBuffers share this buffer (for tests and diagnostics).
  int useCount() const;
  void reset() noexcept;

 private:
  friend class FramePool;
  FrameBuffer(FramePool* pool, std::uint32_t index) noexcept : pool_(pool), index_(index) {}

  FramePool* pool_ = nullptr;
  std::uint32_t index_ = 0;
};

class FramePool {
 public:
  // Boost.Lockfree's fixed-size free list holds at most 65535 nodes and its queue keeps one
  // node spare, so this many buffers can be queued.
  static constexpr std::size_t kMaxBuffers = 65534;

  // Allocates every buffer now. An error for no buffers, empty buffers, more than kMaxBuffers,
  // or a total size that overflows or cannot be allocated.
  static Result<std::unique_ptr<FramePool>> create(std::size_t buffer_count,
                                                   std::size_t buffer_bytes);
  ~FramePool();
  FramePool(const FramePool&) = delete;
  FramePool& operator=(const FramePool&) = delete;

  // A free buffer, or an empty FrameBuffer when every buffer is in use. Never blocks.
  FrameBuffer acquire();

  std::size_t capacity() const { return buffer_count_; }
  std::size_t bufferBytes() const { return buffer_bytes_; }
  // Buffers not held by any FrameBuffer (a snapshot when other threads are active).
  std::size_t available() const { return available_.load(std::memory_order_relaxed); }

 private:
  friend class FrameBuffer;
  FramePool(std::size_t buffer_count, std::size_t buffer_bytes,
            std::unique_ptr<std::uint8_t[]> memory);
  void addReference(std::uint32_t index) noexcept;
  void dropReference(std::uint32_t index) noexcept;
  std::uint8_t* data(std::uint32_t index) const { return memory_.get() + index * buffer_bytes_; }

  std::size_t buffer_count_;
  std::size_t buffer_bytes_;
  std::unique_ptr<std::uint8_t[]> memory_;          // all buffers, contiguous
  std::unique_ptr<std::atomic<int>[]> references_;  // per buffer
  boost::lockfree::queue<std::uint32_t, boost::lockfree::fixed_sized<true>> free_;
  std::atomic<std::size_t> available_;
};

}  // namespace fieldrig::core
