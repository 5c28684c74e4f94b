# Fails when povray_include/libblend.inc differs from what povgen writes now.
execute_process(COMMAND ${POVGEN} ${FRESH} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "povgen failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${COMMITTED} ${FRESH} RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  message(FATAL_ERROR "povray_include/libblend.inc is stale: regenerate it with "
                      "`cmake --build BUILD --target povray-include` and commit it")
endif()
