kincal_test(e2e_cli_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/cli_test.cc
            DEPS kincal_data nlohmann_json::nlohmann_json)
add_dependencies(e2e_cli_test kincal)
