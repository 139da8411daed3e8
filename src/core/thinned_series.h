// A bounded record of an unbounded sequence (per-sample series of a run that
// may last 10^6 steps): every value while there is room; when more than
// `capacity` are kept, every other one is dropped and from then on only
// every 2nd (then 4th, 8th, ...) value is kept, so the kept values stay
// evenly spread over the whole run. The newest value is always kept too.
// Memory is at most capacity + 1 values, whatever the run's length.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace throng {

template <class T>
class ThinnedSeries {
 public:
  explicit ThinnedSeries(std::size_t capacity) : capacity_(capacity < 2 ? 2 : capacity) {}

  void push(T value) {
    const std::uint64_t index = seen_++;
    if (index % stride_ != 0) {
      newest_ = std::move(value);
      return;
    }
    newest_.reset();
    kept_.push_back(std::move(value));
    if (kept_.size() <= capacity_) return;
    // Kept values are those at multiples of the stride; keep the even ones.
    const bool newest_dropped = (kept_.size() - 1) % 2 == 1;
    if (newest_dropped) newest_ = std::move(kept_.back());
    std::size_t out = 1;  // the first stays where it is (no self-move)
    for (std::size_t i = 2; i < kept_.size(); i += 2) kept_[out++] = std::move(kept_[i]);
    kept_.resize(out);
    stride_ *= 2;
  }

  // The kept values in order, the newest last.
  std::vector<T> values() const {
    std::vector<T> v = kept_;
    if (newest_) v.push_back(*newest_);
    return v;
  }
  std::uint64_t seen() const { return seen_; }      // values pushed
  std::uint64_t stride() const { return stride_; }  // 1 while nothing was dropped
  bool empty() const { return seen_ == 0; }
  // The newest value; call only when !empty().
  const T& newest() const { return newest_ ? *newest_ : kept_.back(); }

 private:
  std::size_t capacity_;
  std::uint64_t seen_ = 0;
  std::uint64_t stride_ = 1;
  std::vector<T> kept_;
  std::optional<T> newest_;
};

}  // namespace throng
