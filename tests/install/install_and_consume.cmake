# Script mode: install geods into a scratch prefix, then build and run, against
# the installed tree, a tiny consumer and every ```cpp example of docs/*.md
# (each example is a whole program). Examples run in a folder holding data/.
file(REMOVE_RECURSE ${WORK_DIR})
function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE status WORKING_DIRECTORY ${WORK_DIR}/run)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "failed (${status}): ${ARGV}")
  endif()
endfunction()
file(MAKE_DIRECTORY ${WORK_DIR}/run ${WORK_DIR}/examples)
file(CREATE_LINK ${SOURCE_DIR}/data ${WORK_DIR}/run/data SYMBOLIC)

# Extract the C++ examples.
file(GLOB docs ${SOURCE_DIR}/docs/*.md)
run(/usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/extract_examples.py cpp cpp ${WORK_DIR}/examples ${docs})

run(${CMAKE_COMMAND} --install ${GEODS_BINARY_DIR} --prefix ${WORK_DIR}/prefix)
# The CLI, man page, bash completion and Python package it installed.
if(CHECK_CLI AND CHECK_PYTHON)
  run(/usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/check_installed.py ${WORK_DIR}/prefix)
endif()
find_program(CCACHE ccache)
if(CCACHE)
  set(launcher -DCMAKE_CXX_COMPILER_LAUNCHER=${CCACHE})
endif()
run(${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${WORK_DIR}/build -G Ninja ${launcher}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DEXAMPLES_DIR=${WORK_DIR}/examples)
# It found the installed package, not the build tree's.
file(STRINGS ${WORK_DIR}/build/CMakeCache.txt geods_dir REGEX "^geods_DIR:")
if(NOT geods_dir MATCHES "^geods_DIR:PATH=${WORK_DIR}/prefix/")
  message(FATAL_ERROR "the consumer found geods elsewhere than in the installed prefix: ${geods_dir}")
endif()
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build -j 2)
run(${WORK_DIR}/build/consumer)
file(GLOB examples ${WORK_DIR}/examples/*.cpp)
foreach(example ${examples})
  get_filename_component(name ${example} NAME_WE)
  message(STATUS "running docs example ${name}")
  run(${WORK_DIR}/build/${name})
endforeach()
