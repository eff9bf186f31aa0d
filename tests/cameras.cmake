# End-to-end tests of 1..N cameras (format v3): track and camcal with
# --camera NAME=GLOB, sessions with one folder per camera, one-camera depth
# sigma, cameras that never see the target or share no board view.
kincal_test(e2e_cameras_cli_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/cameras_cli_test.cc
  DEPS kincal_vision kincal_synth nlohmann_json::nlohmann_json)
if(TARGET e2e_cameras_cli_test)
  add_dependencies(e2e_cameras_cli_test kincal)
endif()
# The bundle with one, two and three cameras on rendered sessions.
kincal_test(e2e_cameras_bundle_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/cameras_bundle_test.cc
  DEPS nlohmann_json::nlohmann_json)
if(TARGET e2e_cameras_bundle_test)
  add_dependencies(e2e_cameras_bundle_test kincal)
endif()
