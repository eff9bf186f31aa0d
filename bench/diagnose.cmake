kincal_bench(diagnose_bench SOURCES ${CMAKE_CURRENT_LIST_DIR}/diagnose_bench.cc
             DEPS kincal_synth kincal_diagnose kincal_calib)
