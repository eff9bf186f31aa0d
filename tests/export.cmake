kincal_test(e2e_export_cli_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/export_cli_test.cc
            DEPS kincal_calib nlohmann_json::nlohmann_json)
add_dependencies(e2e_export_cli_test kincal)
