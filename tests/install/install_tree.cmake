# `cmake -DBUILD_DIR=... -DPREFIX=... -P install_tree.cmake`: installs the already built tree
# BUILD_DIR into a fresh PREFIX (nothing is rebuilt; a target not built yet fails the install).
file(REMOVE_RECURSE "${PREFIX}")
execute_process(COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${PREFIX}"
                RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "cmake --install ${BUILD_DIR} --prefix ${PREFIX} failed (${result}):\n"
                      "${out}${err}")
endif()
message(STATUS "installed ${BUILD_DIR} into ${PREFIX}")
