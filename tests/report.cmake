kincal_test(e2e_report_cli_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/report_cli_test.cc
            DEPS kincal_data nlohmann_json::nlohmann_json)
add_dependencies(e2e_report_cli_test kincal)
target_compile_definitions(e2e_report_cli_test PRIVATE
  KINCAL_BUILD_DIR="${CMAKE_BINARY_DIR}")
