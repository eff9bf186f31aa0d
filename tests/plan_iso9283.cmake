# End-to-end tests of `kincal plan --iso9283` (runs build/bin/kincal).
kincal_test(e2e_plan_iso9283_cli_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/plan_iso9283_cli_test.cc
  DEPS kincal_data kincal_calib nlohmann_json::nlohmann_json)
if(TARGET e2e_plan_iso9283_cli_test)
  add_dependencies(e2e_plan_iso9283_cli_test kincal)
endif()
