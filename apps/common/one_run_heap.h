// The heap of a process that estimates one pair and exits.
#pragma once

namespace pnpba {

// Sets glibc's allocator up for a short run: blocks up to 32 MB come from the heap (not from
// mappings of their own, which are returned to the system when freed), the heap grows 24 MB at
// a time, and nothing freed is handed back while the process lives. A pair run touches about 10
// MB of fresh memory; each 4 KB page costs a page fault of 2-12 us on this machine kind, and
// by default the next stage faults a freed block's pages in again. Call once, before the work
// starts. A no-op where the allocator is not glibc's; false when a setting was refused.
bool keepOneRunHeap();

}  // namespace pnpba
