# kincal iso9283 end to end on the demo session (the commands of
# docs/ISO9283.md), with report --iso9283 and diagnose compare.
kincal_test(e2e_iso9283_cli_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/iso9283_cli_test.cc
            DEPS kincal_data nlohmann_json::nlohmann_json)
add_dependencies(e2e_iso9283_cli_test kincal)
