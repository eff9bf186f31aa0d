# End-to-end tests of `kincal camcal` (runs build/bin/kincal).
kincal_test(e2e_camcal_cli_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/camcal_cli_test.cc
  DEPS kincal_camcal nlohmann_json::nlohmann_json)
add_dependencies(e2e_camcal_cli_test kincal)
