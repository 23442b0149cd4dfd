#pragma once
// A client's bounded send queue: frames wait here until the socket takes them; when it is full the
// oldest frame is dropped, so a slow or stalled client loses its oldest samples and never makes the
// server (or the bus behind it) wait.
//
// It also tells a client that reads from one that does not: a run of drops is a sequence of pushes
// that each found the queue full (a push that finds room, because the socket took frames since,
// ends it). A client whose every sample has been dropped for a while reads nothing; the server
// closes it (FoxgloveServer, ServerOptions::stalled_close_seconds) instead of queueing for it
// forever.

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
  /// Appends `frame` at time `now` [s, any monotonic timeline]; when the queue was full, first
  /// drops the oldest frame and returns true.
  bool push(std::string frame, double now) {
    bool dropped = false;
    if (frames_.size() >= capacity_) {
      frames_.pop_front();
      ++dropped_;
      dropped = true;
      if (!dropping_) dropping_since_ = now;
    }
    dropping_ = dropped;
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
  /// [s] How long every push has dropped a frame: `now` minus the time of the first drop of the
  /// current run of drops; 0 when the last push found room (or there was none).
  [[nodiscard]] double dropping_for(double now) const noexcept { return dropping_ ? now - dropping_since_ : 0.0; }
  /// Whether the client reads nothing: every push has dropped a frame for at least `limit` [s] at
  /// `now`. A client that reads at all, however slowly, makes room now and then and never is.
  [[nodiscard]] bool not_reading(double now, double limit) const noexcept {
    return dropping_ && now - dropping_since_ >= limit;
  }

 private:
  std::size_t capacity_;
  std::deque<std::string> frames_;
  std::uint64_t dropped_{0};
  bool dropping_{false};        // the last push dropped a frame
  double dropping_since_{0.0};  // [s] the first drop of the current run
};

}  // namespace crane::web
