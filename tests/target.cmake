# End-to-end tests of `kincal target` on rendered recorded sessions:
# simulate --render -> target (the tag layout against the truth, up to the
# choice of tool frame) -> track with the measured target; bad input.
kincal_test(e2e_target_cli_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/target_cli_test.cc
  DEPS kincal_data kincal_vision kincal_synth nlohmann_json::nlohmann_json)
if(TARGET e2e_target_cli_test)
  add_dependencies(e2e_target_cli_test kincal)
endif()
