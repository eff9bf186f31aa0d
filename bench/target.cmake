# Monte Carlo of `kincal target` (tag layout and pivot tip, error against
# sigma) on rendered sessions of random tool holders.
kincal_bench(target_bench SOURCES ${CMAKE_CURRENT_LIST_DIR}/target_bench.cc
             DEPS kincal_synth kincal_vision)
