kincal_test(e2e_paper_cli_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/paper_cli_test.cc
            DEPS kincal_data nlohmann_json::nlohmann_json)
add_dependencies(e2e_paper_cli_test kincal)
