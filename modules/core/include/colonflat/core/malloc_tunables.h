#pragma once
// The allocator settings every ColonFlat executable runs with (glibc tunables), and the release
// of the memory malloc holds free at the end of each stage.
//
// Why (docs/pipeline.md, "Memory pages"): a page the process gets from the kernel for the first
// time costs a page fault and is zeroed; on the virtual machines measured, whose free memory is
// handed back to the host (free page reporting), first touch costs ~1.5 s of CPU per GiB, while
// rewriting memory the process already holds runs at ~20 GiB/s. glibc by default maps each
// block above its adaptive threshold (at most 32 MiB) afresh and unmaps it on free (one real CT
// run that peaks at 2.6 GB mapped 8.5 GiB in blocks of 4 MiB and more), so the stages paid that
// first touch again and again. The settings:
//   glibc.malloc.hugetlb=1          malloc advises transparent huge pages for what it maps and
//                                   for the heap (one fault per 2 MiB instead of 512);
//   glibc.malloc.mmap_threshold=4 GiB  every block below 4 GiB (all a stage allocates: a float CT of
//                                   512 x 512 x 1024 voxels is 1 GiB) comes from the heap, so a
//                                   block freed is reused by the next allocation, not unmapped;
//   glibc.malloc.trim_threshold=4 GiB  free never shrinks the heap (it must be set together
//                                   with mmap_threshold: either one alone turns off glibc's
//                                   adaptive threshold and maps every block above 128 KiB);
//   glibc.malloc.arena_max=<cores>  one allocation arena per core that can run at the same time:
//                                   memory freed in one arena is not reused by the others, so
//                                   the default (8 per core) strands more held memory.
// What is held free is given back once per stage (release_free_memory, after every stage), so
// the process peak stays that of its largest stage.
// glibc reads tunables only at start-up, from the environment, so an executable runs itself again
// with the variable set (rerun_with_malloc_tunables, the first line of main). A user who sets
// any glibc.malloc tunable in GLIBC_TUNABLES is obeyed as given (nothing is added), e.g.
// GLIBC_TUNABLES=glibc.malloc.hugetlb=1 for the allocator of session 22. Without transparent
// huge pages (/sys/kernel/mm/transparent_hugepage/enabled = never) hugetlb changes nothing.
#include <string>

namespace cf {

// GLIBC_TUNABLES with ColonFlat's malloc settings (above; arena_max = `cores`, at least 1)
// added to `current` (nullptr: unset), or "" when `current` already sets a glibc.malloc tunable
// (nothing to change).
std::string tunables_for_colonflat(const char* current, unsigned cores);

// When the environment sets no glibc.malloc tunable yet: sets ColonFlat's (cores: the machine's)
// and replaces this process with a fresh run of the same executable (/proc/self/exe) and the
// same argv (argv[argc] must be nullptr, as main's is). Returns only when nothing had to change
// or the exec failed (the program then simply runs with glibc's defaults). Call before anything
// else in main.
void rerun_with_malloc_tunables(char** argv);

// The GLIBC_TUNABLES this process runs with ("" when unset), recorded in stage reports.
std::string malloc_tunables();

// Gives the memory malloc holds free, in every arena, back to the kernel (malloc_trim(0)).
// Called by the stage runner after every stage: what the stage freed no longer counts against
// the next one's peak.
void release_free_memory();

}  // namespace cf
