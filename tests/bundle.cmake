# End-to-end tests of `kincal bundle` on rendered recorded sessions:
# simulate --render -> bundle (and the two-step track -> calibrate) ->
# evaluate on fresh noise-free true tips; bad input; backlash from images.
kincal_test(e2e_bundle_cli_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/bundle_cli_test.cc
  DEPS kincal_data nlohmann_json::nlohmann_json)
if(TARGET e2e_bundle_cli_test)
  add_dependencies(e2e_bundle_cli_test kincal)
endif()
