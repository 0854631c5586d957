#pragma once
// Every large malloc block on transparent huge pages, for the whole process.
//
// Why: the stages fill volume- and mesh-sized arrays once and drop them; each fresh 4 KiB page
// costs a page fault, and on virtual machines those faults were a third of segment's CPU (real
// CT: 321,671 minor faults). glibc's tunable glibc.malloc.hugetlb=1 makes malloc advise huge
// pages (MADV_HUGEPAGE) for the blocks it maps and the heap it grows, so one fault brings in
// 2 MiB: the same segment run takes 16,397 faults and 24 % less CPU, with the same peak memory.
// glibc reads tunables only at start-up, from the environment, so an executable that wants them
// runs itself again with the variable set (rerun_with_huge_page_malloc, the first line of main).
// A user who sets glibc.malloc.hugetlb in GLIBC_TUNABLES (e.g. =0 to turn it off) is obeyed.
// Without transparent huge pages (/sys/kernel/mm/transparent_hugepage/enabled = never) the advice
// changes nothing.
#include <string>

namespace cf {

// GLIBC_TUNABLES with glibc.malloc.hugetlb=1 added to `current` (nullptr: unset), or "" when
// `current` already sets glibc.malloc.hugetlb (nothing to change).
std::string tunables_with_huge_page_malloc(const char* current);

// When the environment does not yet set glibc.malloc.hugetlb: sets it and replaces this process
// with a fresh run of the same executable (/proc/self/exe) and the same argv (argv[argc] must be
// nullptr, as main's is). Returns only when nothing had to change or the exec failed (the
// program then simply runs without the tunable). Call before anything else in main.
void rerun_with_huge_page_malloc(char** argv);

// The GLIBC_TUNABLES this process runs with ("" when unset), recorded in stage reports.
std::string malloc_tunables();

}  // namespace cf
