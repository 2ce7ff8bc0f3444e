# The sanitizer builds compile one Highway target (HWY_COMPILE_ONLY_STATIC): AVX2 (-march=haswell)
# where this machine has it (the main build's dispatch runs AVX2 or AVX-512 there), else the
# baseline EMU128, whose emulated lanes run 10 to 100 times slower under the sanitizers. No contraction
# into FMAs outside the kernels, as in the main build. Sets simd_flags, avx2 and unity.
file(READ /proc/cpuinfo cpuinfo)
set(avx2 OFF)
if(cpuinfo MATCHES " avx2" AND cpuinfo MATCHES " fma" AND cpuinfo MATCHES " f16c" AND cpuinfo MATCHES " bmi2")
  set(avx2 ON)
endif()
set(simd_flags "-DHWY_COMPILE_ONLY_STATIC=1")
if(avx2)
  string(APPEND simd_flags " -march=haswell -ffp-contract=off")
endif()

# Unity builds (eight sources a compile): the sanitizer builds share the machine with the main
# suite, and most of their time went to parsing the same headers again.
set(unity -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=8)
