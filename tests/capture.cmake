# End-to-end tests of `kincal capture` (runs build/bin/kincal).
kincal_test(e2e_capture_cli_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/capture_cli_test.cc
  DEPS kincal_capture nlohmann_json::nlohmann_json)
if(TARGET e2e_capture_cli_test)
  add_dependencies(e2e_capture_cli_test kincal)
endif()
kincal_test(e2e_capture_joints_cli_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/capture_joints_cli_test.cc
  DEPS kincal_capture nlohmann_json::nlohmann_json)
if(TARGET e2e_capture_joints_cli_test)
  add_dependencies(e2e_capture_joints_cli_test kincal)
endif()
kincal_test(e2e_capture_robot_cli_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/capture_robot_cli_test.cc
  DEPS kincal_capture nlohmann_json::nlohmann_json)
if(TARGET e2e_capture_robot_cli_test)
  add_dependencies(e2e_capture_robot_cli_test kincal)
endif()
# 1..N cameras: rendered sessions (1 and 3 cameras) replayed through capture
# --camera NAME=URI with a joint log; track and bundle --session read the
# same.
kincal_test(e2e_capture_cameras_cli_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/capture_cameras_cli_test.cc
  DEPS kincal_capture nlohmann_json::nlohmann_json)
if(TARGET e2e_capture_cameras_cli_test)
  add_dependencies(e2e_capture_cameras_cli_test kincal)
endif()
