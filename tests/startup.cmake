# bin/kincal without image libraries, one command surface with kincal-vision
# (app/front_end.h, docs/STARTUP.md).
kincal_test(e2e_startup_cli_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/startup_cli_test.cc
            DEPS kincal_data)
add_dependencies(e2e_startup_cli_test kincal kincal-vision)

# `cmake --install` puts both executables in PREFIX/bin and the installed
# kincal runs an image command through the installed kincal-vision.
if(KINCAL_BUILD_TESTS)
  add_test(NAME Install.PutsBothExecutablesOnThePath
           COMMAND sh -c "rm -rf install-test && \
${CMAKE_COMMAND} --install ${PROJECT_BINARY_DIR} --prefix install-test >/dev/null && \
PATH=$PWD/install-test/bin:/usr/bin:/bin && cd / && \
kincal --version | grep -q commit && \
kincal camcal --help | grep -q 'kincal camcal' && \
test \"$(command -v kincal-vision)\" = \"$OLDPWD/install-test/bin/kincal-vision\""
           WORKING_DIRECTORY ${PROJECT_BINARY_DIR})
endif()
