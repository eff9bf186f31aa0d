# Pose planning: planned vs random poses, predicted and confirmed by
# simulated calibrations (prints a table; not a timing benchmark).
kincal_bench(plan_bench
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/plan_bench.cc
  DEPS kincal_plan kincal_synth)
