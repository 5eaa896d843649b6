#include "spacar/limits.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "spacar/errors.hpp"

namespace spacar {

namespace {
std::atomic<std::size_t> g_memory_limit{std::size_t(4) << 30};
thread_local ThreadDeadline t_deadline;
thread_local InterruptScope::Poll t_interrupt = nullptr;
thread_local std::chrono::steady_clock::time_point t_last_poll;
thread_local const std::atomic<bool>* t_cancel = nullptr;
}  // namespace

InterruptScope::InterruptScope(Poll poll) : outer_(t_interrupt) {
  t_interrupt = poll;
  t_last_poll = std::chrono::steady_clock::now();
}

InterruptScope::~InterruptScope() { t_interrupt = outer_; }

CancelScope::CancelScope(const std::atomic<bool>* flag) : outer_(t_cancel) { t_cancel = flag; }

CancelScope::~CancelScope() { t_cancel = outer_; }

void check_thread_interrupt() {
  if (t_cancel && t_cancel->load(std::memory_order_relaxed)) throw Interrupted("the analysis was cancelled");
  if (!t_interrupt) return;
  constexpr auto kPollInterval = std::chrono::milliseconds(20);  // the poll takes the GIL
  const auto now = std::chrono::steady_clock::now();
  if (now - t_last_poll < kPollInterval) return;
  t_last_poll = now;
  if (t_interrupt()) throw Interrupted("the analysis was interrupted (KeyboardInterrupt)");
}

bool thread_deadline_passed() { return t_deadline.active && std::chrono::steady_clock::now() > t_deadline.at; }

void throw_time_limit(const std::string& where) {
  std::ostringstream os;
  os << "the time limit of " << t_deadline.seconds << " s was exceeded " << where;
  throw TimeLimitError(os.str());
}

void check_thread_deadline(const char* where) {
  if (thread_deadline_passed()) throw_time_limit(where);
  check_thread_interrupt();
}

DeadlineScope::DeadlineScope(double limit, double spent) : outer_(t_deadline) {
  constexpr double kNoLimit = 1e9;  // seconds (31 years): also keeps the clock arithmetic finite
  if (!(limit > 0.0 && limit < kNoLimit)) return;
  const auto at = std::chrono::steady_clock::now() +
                  std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                      std::chrono::duration<double>(limit - std::max(spent, 0.0)));
  if (!outer_.active || at < outer_.at) t_deadline = ThreadDeadline{true, limit, at};
}

DeadlineScope::~DeadlineScope() { t_deadline = outer_; }

std::size_t memory_limit() { return g_memory_limit.load(); }

void set_memory_limit(std::size_t bytes) { g_memory_limit.store(bytes); }

std::string format_bytes(double bytes) {
  static const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
  int u = 0;
  while (bytes >= 1000.0 && u < 6) {
    bytes /= 1000.0;
    ++u;
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.3g %s", bytes, units[u]);
  return buf;
}

void require_memory(double bytes, const std::string& what, const std::string& hint) {
  const double limit = static_cast<double>(memory_limit());
  if (bytes > limit)
    throw InputError(what + " would need " + format_bytes(bytes) + ", more than the memory limit of " +
                     format_bytes(limit) + " (spacar.set_memory_limit)" + (hint.empty() ? "" : "; " + hint));
}

}  // namespace spacar
