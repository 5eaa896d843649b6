#include "spacar/limits.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "spacar/errors.hpp"

namespace spacar {

namespace {
std::atomic<std::size_t> g_memory_limit{std::size_t(4) << 30};

struct ThreadDeadline {
  bool active = false;
  double seconds = 0.0;
  std::chrono::steady_clock::time_point at;
};
thread_local ThreadDeadline t_deadline;
}  // namespace

void set_thread_deadline(double seconds, double limit) {
  t_deadline.active = seconds > 0.0 && std::isfinite(seconds);
  t_deadline.seconds = limit;
  if (t_deadline.active)
    t_deadline.at = std::chrono::steady_clock::now() +
                    std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
}

void clear_thread_deadline() { t_deadline.active = false; }

void check_thread_deadline(const char* where) {
  if (!t_deadline.active || std::chrono::steady_clock::now() <= t_deadline.at) return;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", t_deadline.seconds);
  throw TimeLimitError(std::string("the time limit of ") + buf + " s was exceeded (" + where + ")");
}

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
