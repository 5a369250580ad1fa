# check_manner.cmake: one program's manners (CONTRIBUTING.md, "Programs"):
# `PROG --version` exits 0 with "NAME X.Y.Z (commit C, BUILD_TYPE)" on one
# line, and an unknown option exits 2 with exactly one line on stderr,
# "NAME: unknown option '--no-such-option' (see --help)". Run by CTest as
# test_manner_NAME with -DPROG=path -DNAME=name.
execute_process(COMMAND ${PROG} --version RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${NAME} --version exited ${rc}: ${out}${err}")
endif()
if(NOT out MATCHES "^${NAME} [0-9]+\\.[0-9]+\\.[0-9]+ \\(commit ([0-9a-f]+|unknown), [A-Za-z]+\\)\n$")
  message(FATAL_ERROR "${NAME} --version printed '${out}'")
endif()
execute_process(COMMAND ${PROG} --no-such-option RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2)
  message(FATAL_ERROR "${NAME} --no-such-option exited ${rc}")
endif()
if(NOT err STREQUAL "${NAME}: unknown option '--no-such-option' (see --help)\n")
  message(FATAL_ERROR "${NAME} --no-such-option printed '${err}' (want one line)")
endif()
message(STATUS "${NAME}: ${out}")
