kincal_bench(paper_bench SOURCES ${CMAKE_CURRENT_LIST_DIR}/paper_bench.cc
             DEPS kincal_synth kincal_calib kincal_data)
