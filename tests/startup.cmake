# bin/kincal without image libraries, one command surface with kincal-vision
# (app/front_end.h, docs/STARTUP.md).
kincal_test(e2e_startup_cli_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/startup_cli_test.cc
            DEPS kincal_data)
add_dependencies(e2e_startup_cli_test kincal kincal-vision)
