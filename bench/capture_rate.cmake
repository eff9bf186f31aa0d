# Recording at camera rate: N fake 1280x1024 cameras at 30 fps (argv[2],
# default 2) through the grouping, the bounded queue and the writer threads
# for 60 s (argv[1], real time), and folder replay as fast as it goes.
# Prints a table.
kincal_bench(capture_rate_bench
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/capture_rate_bench.cc
  DEPS kincal_capture)
