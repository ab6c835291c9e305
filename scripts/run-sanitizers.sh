#!/usr/bin/env bash
# The sanitizer job: builds in ./build-asan the readers (common/, segmentation_io/,
# solver/io, the checkpoint archive) with -fsanitize=address,undefined (cmake/
# StentsimSanitize.cmake; the rest keeps the normal build's flags and comes from
# ccache) and runs the reader tests and the quick fuzz tests under ASan and UBSan.
# Any report fails it. Usage: bash scripts/run-sanitizers.sh (after scripts/build.sh,
# which installs the packages; run-tests.sh calls it last).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
start=$(date +%s)
tests=(test_common test_segmentation_io_label_image test_segmentation_io_simvascular test_segmentation_io_surface_input
       test_segmentation_io_reader_fuzz test_fuzz_label_images test_fuzz_simvascular test_fuzz_yaml test_fuzz_checkpoint test_fuzz_vtk_xml)
cmake -S "$here" -B "$here/build-asan" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSTENTSIM_SANITIZE=ON > /dev/null
# One job per core at most: an instrumented VTK-heavy translation unit takes over 1 GB.
cmake --build "$here/build-asan" --target "${tests[@]}" -j "$(nproc)"
# exitcode: a sanitizer report is a failure ctest sees. max_allocation_size_mb: ASan reserves
# terabytes of shadow memory, so ulimit -v cannot bound a run; allocations above 4 GB fail
# instead (malloc returns null, new reports). Leaks inside VTK's, Trilinos' and Open
# MPI's own singletons are suppressed by library name (scripts/lsan-suppressions.txt);
# the solver's run (Trilinos, MPI) gets fast_unwind_on_malloc=0, whole stacks for its
# allocations (Debian's libraries keep no frame pointers), so the names match; it
# would make the other tests five times slower.
# The solves inside the checkpoint fuzzing run their element loops on one thread: TBB's
# worker pool keeps allocations past exit that LeakSanitizer would report, and the readers
# are what this job checks.
export STENTSIM_THREADS=1
# VTK's parallel loops run sequentially (VTK 9.1 picks its SMP backend from this variable):
# the readers fork a child to probe a VTK XML file, and a child forked while TBB's workers
# are alive in the instrumented parent can hang until the probe's 20 s limit.
export VTK_SMP_BACKEND_IN_USE=Sequential
# The fuzz tests' per-input bound (30 s, the release build's) times three: under ASan a
# zlib .vtu mutant whose blocks claim gigabytes took 36 s (read twice: the probe child,
# then the reader) with the other core busy; the release build reads all 1,200 in 41 s.
export STENTSIM_FUZZ_SECONDS=90
# The fuzz tests' memory bound (2 GB over the start, the release build's) plus a GB: ASan's
# allocator keeps up to 256 MB of freed blocks in quarantine, adds redzones to every block
# and its shadow memory grows with what the reader touches.
export STENTSIM_FUZZ_MEGABYTES=3072
export ASAN_OPTIONS="exitcode=86:max_allocation_size_mb=4096:allocator_may_return_null=1:detect_leaks=1:abort_on_error=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:exitcode=86"
export LSAN_OPTIONS="suppressions=$here/scripts/lsan-suppressions.txt:print_suppressions=0"
regex="^($(IFS='|'; echo "${tests[*]}"))\\."
ctest --test-dir "$here/build-asan" -R "$regex" -E "^test_fuzz_checkpoint\\." -L quick --output-on-failure -j "$(nproc)" --timeout 900
ASAN_OPTIONS="$ASAN_OPTIONS:fast_unwind_on_malloc=0" \
  ctest --test-dir "$here/build-asan" -R "^test_fuzz_checkpoint\\." -L quick --output-on-failure --timeout 900
echo "run-sanitizers: $(( $(date +%s) - start )) s"
