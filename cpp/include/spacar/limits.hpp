// Resource limits of an analysis: no input may exhaust the machine's memory. Every large
// allocation that an input can make arbitrarily large (the work arrays of an analysis, which
// are dense in the number of coordinates; the result arrays, proportional to the number of
// output times; the constraint diagnosis) is checked against one process-wide limit first, and
// refused with an InputError that says what needs the memory and how to reduce it.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <string>

namespace spacar {

// Bytes one analysis may allocate for its work and result arrays (default 4 GiB).
std::size_t memory_limit();
void set_memory_limit(std::size_t bytes);

// Throws InputError if `bytes` exceeds memory_limit(): "<what> would need <bytes>, more than
// the memory limit of <limit>; <hint>".
void require_memory(double bytes, const std::string& what, const std::string& hint);

// "1.5 GB", "12 kB", ...
std::string format_bytes(double bytes);

// The wall-clock deadline of the analysis running on this thread (a run's time_limit, set by a
// DeadlineScope), checked also inside the long computations that no step of the integrator
// interrupts — the sparse factorizations of large systems — so that a time limit bounds a run
// whatever its size. Thread-local: the sweep runs analyses in threads side by side.
struct ThreadDeadline {
  bool active = false;
  double seconds = 0.0;  // the time limit that the message names
  std::chrono::steady_clock::time_point at;
};
bool thread_deadline_passed();
// TimeLimitError "the time limit of <limit> s was exceeded <where>".
[[noreturn]] void throw_time_limit(const std::string& where);
// throw_time_limit(where) if the deadline has passed.
void check_thread_deadline(const char* where);

// An interruption of the analysis running on this thread: `poll` (the bindings': Python's
// pending Ctrl-C) is asked, at most every 20 ms, wherever the deadline is checked, for the
// lifetime of the scope; when it answers true, check_thread_interrupt throws Interrupted.
class InterruptScope {
 public:
  using Poll = bool (*)();
  explicit InterruptScope(Poll poll);
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;

 private:
  Poll outer_;
};
void check_thread_interrupt();

// A cancellation of the analyses running on the threads that watch `flag` (a sweep's threads,
// which Python's Ctrl-C does not reach): once the flag is set, check_thread_interrupt throws
// Interrupted on each of them, without waiting for the poll's interval. Nested scopes restore
// the outer flag.
class CancelScope {
 public:
  explicit CancelScope(const std::atomic<bool>* flag);
  ~CancelScope();
  CancelScope(const CancelScope&) = delete;
  CancelScope& operator=(const CancelScope&) = delete;

 private:
  const std::atomic<bool>* outer_;
};

// The deadline of `limit` seconds (0 or beyond 10⁹ s: none) from `spent` seconds ago, for the
// lifetime of the scope (a run, a set-up, a diagnosis). Nested scopes (an analysis started from
// a callback of another) keep the earlier deadline and restore the outer one when they end.
class DeadlineScope {
 public:
  explicit DeadlineScope(double limit, double spent = 0.0);
  ~DeadlineScope();
  DeadlineScope(const DeadlineScope&) = delete;
  DeadlineScope& operator=(const DeadlineScope&) = delete;

 private:
  ThreadDeadline outer_;
};

}  // namespace spacar
