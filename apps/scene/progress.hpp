#pragma once
// Progress of a long run on a terminal: steps done, rate and time left, rewritten in place at
// most every 0.5 s on stderr. Silent when stderr is not a terminal (CI logs, pipes).
#include <unistd.h>

#include <chrono>
#include <cstdio>

namespace stokescontact::apps {

class Progress {
 public:
  explicit Progress(long long total_steps, bool enabled = isatty(fileno(stderr)) != 0)
      : total_(total_steps), enabled_(enabled), start_(std::chrono::steady_clock::now()), last_(start_) {}

  void update(long long done) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (done < total_ && now - last_ < std::chrono::milliseconds(500)) return;
    last_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double rate = elapsed > 0.0 ? static_cast<double>(done) / elapsed : 0.0;
    const double left = rate > 0.0 ? static_cast<double>(total_ - done) / rate : 0.0;
    std::fprintf(stderr, "\r  step %lld / %lld (%.0f%%), %.1f steps/s, %.0f s left   ", done, total_,
                 100.0 * static_cast<double>(done) / static_cast<double>(total_), rate, left);
    std::fflush(stderr);
  }

  void finish() {
    if (enabled_) std::fprintf(stderr, "\n");
  }

 private:
  long long total_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace stokescontact::apps
