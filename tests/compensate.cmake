# `kincal compensate`: simulated round trips (simulate -> diagnose ->
# compensate -> executed on the true robot) and the command's contract.
kincal_test(e2e_compensate_cli_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/compensate_cli_test.cc
  DEPS kincal_calib nlohmann_json::nlohmann_json)
add_dependencies(e2e_compensate_cli_test kincal)
