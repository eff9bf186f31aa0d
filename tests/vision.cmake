# End-to-end test of `kincal track` on rendered stereo frames.
kincal_test(e2e_track_cli_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/track_cli_test.cc
  DEPS kincal_vision kincal_synth nlohmann_json::nlohmann_json)
if(TARGET e2e_track_cli_test)
  add_dependencies(e2e_track_cli_test kincal)
endif()
