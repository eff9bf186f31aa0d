# Writes OUT, a header defining KINCAL_COMMIT (`git describe --always
# --dirty` of SOURCE_DIR, or "unknown" outside a git checkout), for
# `kincal --version`. Run at every build (app/CMakeLists.txt); the header is
# rewritten only when the commit changes, so only main.cc recompiles.
execute_process(
  COMMAND git -C "${SOURCE_DIR}" describe --always --dirty --abbrev=12
  OUTPUT_VARIABLE commit
  OUTPUT_STRIP_TRAILING_WHITESPACE
  ERROR_QUIET
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR commit STREQUAL "")
  set(commit "unknown")
endif()
file(WRITE "${OUT}.tmp" "#define KINCAL_COMMIT \"${commit}\"\n")
execute_process(COMMAND "${CMAKE_COMMAND}" -E copy_if_different "${OUT}.tmp" "${OUT}")
file(REMOVE "${OUT}.tmp")
