kincal_bench(calib_bench SOURCES ${CMAKE_CURRENT_LIST_DIR}/calib_bench.cc
             DEPS kincal_synth kincal_calib)
