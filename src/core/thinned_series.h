// A bounded record of an unbounded sequence (per-sample series of a run that
// may last 10^6 steps): every value while there is room; when more than
// `capacity` are kept, every other one is dropped and from then on only
// every 2nd (then 4th, 8th, ...) value is kept, so the kept values stay
// evenly spread over the whole run. The newest value is always kept too.
// Memory is at most capacity + 1 values, whatever the run's length.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
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
      newest_.assign(1, std::move(value));
      return;
    }
    newest_.clear();
    kept_.push_back(std::move(value));
    if (kept_.size() <= capacity_) return;
    // Kept values are those at multiples of the stride; keep the even ones.
    const bool newest_dropped = (kept_.size() - 1) % 2 == 1;
    if (newest_dropped) newest_.assign(1, std::move(kept_.back()));
    std::size_t out = 1;  // the first stays where it is (no self-move)
    for (std::size_t i = 2; i < kept_.size(); i += 2) kept_[out++] = std::move(kept_[i]);
    kept_.resize(out);
    stride_ *= 2;
  }

  // The kept values in order, the newest last.
  std::vector<T> values() const {
    std::vector<T> v = kept_;
    v.insert(v.end(), newest_.begin(), newest_.end());
    return v;
  }
  std::uint64_t seen() const { return seen_; }      // values pushed
  std::uint64_t stride() const { return stride_; }  // 1 while nothing was dropped
  bool empty() const { return seen_ == 0; }
  // The newest value; call only when !empty().
  const T& newest() const { return newest_.empty() ? kept_.back() : newest_.front(); }

 private:
  std::size_t capacity_;
  std::uint64_t seen_ = 0;
  std::uint64_t stride_ = 1;
  std::vector<T> kept_;
  // The newest value when it is not kept: none or one (a vector, not an
  // optional: GCC 12 warns of a maybe-uninitialized optional<double> copy).
  std::vector<T> newest_;
};

// Numbers of an unbounded sequence (frame times, foot slides of a long
// run): count, mean and maximum exact, and a ThinnedSeries of the values
// for percentiles (exact while nothing was dropped, then over the evenly
// spread values kept).
class ThinnedSample {
 public:
  explicit ThinnedSample(std::size_t capacity) : kept_(capacity) {}

  void push(double v) {
    max_ = count_ == 0 ? v : std::max(max_, v);
    ++count_;
    sum_ += v;
    kept_.push(v);
  }
  std::uint64_t count() const { return count_; }
  double mean() const { return count_ > 0 ? sum_ / static_cast<double>(count_) : 0.0; }
  double max() const { return max_; }  // 0 for no values
  std::vector<double> values() const { return kept_.values(); }
  std::uint64_t stride() const { return kept_.stride(); }

 private:
  ThinnedSeries<double> kept_;
  std::uint64_t count_ = 0;
  double sum_ = 0.0, max_ = 0.0;
};

}  // namespace throng
