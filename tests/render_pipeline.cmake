kincal_test(e2e_render_pipeline_test
            SOURCES ${CMAKE_CURRENT_LIST_DIR}/render_pipeline_test.cc
            DEPS kincal_data nlohmann_json::nlohmann_json)
add_dependencies(e2e_render_pipeline_test kincal)
