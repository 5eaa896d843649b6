// Resource limits of an analysis: no input may exhaust the machine's memory. Every large
// allocation that an input can make arbitrarily large (the work arrays of an analysis, which
// are dense in the number of coordinates; the result arrays, proportional to the number of
// output times; the constraint diagnosis) is checked against one process-wide limit first, and
// refused with an InputError that says what needs the memory and how to reduce it.
#pragma once

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

}  // namespace spacar
