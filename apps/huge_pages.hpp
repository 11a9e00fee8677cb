#pragma once
// Large allocations on transparent huge pages, for the long commands.

#include <string>

namespace pitchlab::apps {

/// GLIBC_TUNABLES with glibc's malloc asked to back its large blocks with transparent huge pages
/// (glibc.malloc.hugetlb=1, glibc 2.35+), appended to `current` (the variable's value, may be
/// empty); empty when `current` sets that tunable already (the user's choice stands).
std::string WithHugePageMalloc(const std::string& current);

/// Where the kernel gives huge pages only on request ("[madvise]" in `thp_enabled`, the text of
/// /sys/kernel/mm/transparent_hugepage/enabled: Debian's default) and GLIBC_TUNABLES does not set
/// glibc.malloc.hugetlb, re-executes this program (/proc/self/exe, same arguments, same pid) with
/// it set, so that glibc reads it at start-up; else, or when the exec fails, returns and the
/// program runs on as it is (the same results, slower). Runs and sweeps touch hundreds of MB of
/// fresh buffers (grids of every stop, MuJoCo's and the truth's data), and this VM's kernel takes
/// a fault per 4 KB page: urban seed 5 took 88 k faults and 8.3 s of CPU with 4 KB pages, 32 k and
/// 7.5 s with huge pages (wall 6.0 -> 5.2 s); terrain seed 1 118 k -> 46 k faults, wall 9.7 ->
/// 8.7 s. The results are the same bits. Costs one more start-up of the program (0.2 s: the
/// shared libraries' relocations). Not under the sanitizers, whose allocator ignores the tunable.
void UseHugePagesForLargeAllocations(char** argv);

}  // namespace pitchlab::apps
