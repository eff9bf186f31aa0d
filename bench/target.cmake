# Monte Carlo of `kincal target` (tag layout and pivot tip, error against
# sigma) on rendered sessions of random tool holders.
kincal_bench(target_bench SOURCES ${CMAKE_CURRENT_LIST_DIR}/target_bench.cc
             DEPS kincal_synth kincal_vision)
# What error a session's views share (the corners' bias, seed by seed).
kincal_bench(target_bias_bench
             SOURCES ${CMAKE_CURRENT_LIST_DIR}/target_bias_bench.cc
             DEPS kincal_synth kincal_vision)
# Each side's edge error by projected motion blur and cell size over blur.
kincal_bench(blur_sides_bench
             SOURCES ${CMAKE_CURRENT_LIST_DIR}/blur_sides_bench.cc
             DEPS kincal_synth kincal_vision)
