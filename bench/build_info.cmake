# Run at build time (cmake -P) by the target geodex_bench_build_info: writes OUT, a header with the
# git commit of SRC and whether core/ had uncommitted changes when geodex_bench was built. The file
# is rewritten only when that changes, so it costs no recompilation otherwise.
# GIT_OPTIONAL_LOCKS=0: `git status` must not refresh (write) the index of a tree others work in.
# COMMIT, when not empty, is used as given (a snapshot that is not a git checkout).
set(dirty "")
if(NOT COMMIT STREQUAL "")
  set(commit "${COMMIT}")
else()
  execute_process(COMMAND git -C ${SRC} rev-parse --short HEAD
                  OUTPUT_VARIABLE commit OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env GIT_OPTIONAL_LOCKS=0
                          git -C ${SRC} status --porcelain --untracked-files=no -- core
                  OUTPUT_VARIABLE dirty ERROR_QUIET)
  if(commit STREQUAL "")
    set(commit "unknown")
  endif()
endif()
if(NOT dirty STREQUAL "")
  string(APPEND commit " + uncommitted changes under core/")
endif()
file(WRITE ${OUT}.tmp "#define GEODEX_BENCH_BUILT_FROM \"${commit}\"\n")
file(COPY_FILE ${OUT}.tmp ${OUT} ONLY_IF_DIFFERENT)
file(REMOVE ${OUT}.tmp)
