#pragma once

// Peak memory of this process, from the kernel (Linux /proc). A measurement resets the RSS
// high-water mark once its input is loaded; its peak is then what it needed on top of that
// (the child runner reads the same high-water mark of a child as ru_maxrss from wait4).

#include <cstdint>

namespace geodex::bench {

// The resident size of this process now (/proc/self/statm), in KiB.
int64_t CurrentRssKb();
// Resets the kernel's RSS high-water mark of this process to its current RSS
// (/proc/self/clear_refs "5"); false if the kernel refused.
bool ResetRssHighWater();
// The kernel's RSS high-water mark of this process (VmHWM), in KiB.
int64_t PeakRssKb();

}  // namespace geodex::bench
