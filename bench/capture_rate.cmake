# Recording at camera rate: two fake 1280x1024 cameras at 30 fps through the
# pairing, the bounded queue and the writer threads for 60 s (real time),
# and folder replay as fast as it goes. Prints a table.
kincal_bench(capture_rate_bench
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/capture_rate_bench.cc
  DEPS kincal_capture)
