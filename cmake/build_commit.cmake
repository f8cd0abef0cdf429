# Writes generated/dynbench/build_commit.h at every build (the target dynbench_build_commit): the
# commit HEAD names, with "-dirty" when tracked files differ from it, so that a suite record made by
# a build of uncommitted changes says so instead of naming a commit whose code it is not.
# configure_file rewrites the header only when its text changes, so an unchanged tree recompiles
# nothing. Run as: cmake -DSOURCE_DIR=... -DOUTPUT=... -DGIT_EXECUTABLE=... -P build_commit.cmake
set(DYNBENCH_BUILD_COMMIT "unknown")
if(GIT_EXECUTABLE AND EXISTS "${SOURCE_DIR}/.git")
  execute_process(COMMAND "${GIT_EXECUTABLE}" rev-parse HEAD WORKING_DIRECTORY "${SOURCE_DIR}"
                  OUTPUT_VARIABLE commit OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE failed)
  if(NOT failed AND commit)
    set(DYNBENCH_BUILD_COMMIT "${commit}")
    execute_process(COMMAND "${GIT_EXECUTABLE}" status --porcelain --untracked-files=no WORKING_DIRECTORY "${SOURCE_DIR}"
                    OUTPUT_VARIABLE changes OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(changes)
      set(DYNBENCH_BUILD_COMMIT "${commit}-dirty")
    endif()
  endif()
endif()
configure_file("${SOURCE_DIR}/src/core/build_commit.h.in" "${OUTPUT}" @ONLY)
