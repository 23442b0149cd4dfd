#pragma once
// A client's bounded send queue: frames wait here until the socket takes them; when it is full the
// oldest frame is dropped, so a slow or stalled client loses its oldest samples and never makes the
// server (or the bus behind it) wait.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <stdexcept>
#include <string>
#include <utility>

namespace crane::web {

class SendQueue {
 public:
  /// `capacity`: frames held at most (>= 1). Throws std::invalid_argument naming the value.
  explicit SendQueue(std::size_t capacity) : capacity_(capacity) {
    if (capacity == 0) throw std::invalid_argument("web.queue = 0 frames: must be at least 1");
  }
  /// Appends `frame`; when the queue was full, first drops the oldest frame and returns true.
  bool push(std::string frame) {
    bool dropped = false;
    if (frames_.size() >= capacity_) {
      frames_.pop_front();
      ++dropped_;
      dropped = true;
    }
    frames_.push_back(std::move(frame));
    return dropped;
  }
  /// Moves the oldest frame into `frame`; false when empty.
  bool pop(std::string& frame) {
    if (frames_.empty()) return false;
    frame = std::move(frames_.front());
    frames_.pop_front();
    return true;
  }
  [[nodiscard]] std::size_t size() const noexcept { return frames_.size(); }
  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }
  /// Frames dropped since construction.
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_; }

 private:
  std::size_t capacity_;
  std::deque<std::string> frames_;
  std::uint64_t dropped_{0};
};

}  // namespace crane::web
