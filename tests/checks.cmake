# End-to-end tests of the input checks (refusals and warnings on inputs that
# parse but look wrong; runs build/bin/kincal).
kincal_test(e2e_checks_cli_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/checks_cli_test.cc
  DEPS kincal_capture nlohmann_json::nlohmann_json)
if(TARGET e2e_checks_cli_test)
  add_dependencies(e2e_checks_cli_test kincal)
endif()
