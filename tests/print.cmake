# End-to-end tests of `kincal print` (runs build/bin/kincal; the 600 dpi size
# check needs pdftoppm from poppler-utils and skips without it).
kincal_test(e2e_print_cli_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/print_cli_test.cc
  DEPS kincal_data ${OpenCV_LIBS} nlohmann_json::nlohmann_json)
add_dependencies(e2e_print_cli_test kincal)
