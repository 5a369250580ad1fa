# EmbedBytes.cmake: what the build-time embedding scripts share
# (common/sl/standard/embed.cmake, master/monitor_page/embed.cmake): a
# file's bytes as C initializers, and writing the generated C file only
# when it changed (an unchanged set rebuilds nothing). Bytes, not string
# literals: no escaping to get wrong, any byte is fine.

# embed_bytes(FILE BYTES_VAR LEN_VAR): "0xab,0xcd,..." (16 a line, the
# lines joined by "\n    ") and the byte count
function(embed_bytes file bytes_var len_var)
  file(READ "${file}" hex HEX)
  string(LENGTH "${hex}" nhex)
  math(EXPR len "${nhex} / 2")
  string(REPEAT "0x[0-9a-f][0-9a-f]," 16 line16)
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
  string(REGEX REPLACE "(${line16})" "\\1\n    " bytes "${bytes}")
  set(${bytes_var} "${bytes}" PARENT_SCOPE)
  set(${len_var} "${len}" PARENT_SCOPE)
endfunction()

# embed_write(OUT BODY): writes BODY to OUT unless OUT already holds it
function(embed_write out body)
  if(EXISTS "${out}")
    file(READ "${out}" old)
    if(old STREQUAL body)
      return()
    endif()
  endif()
  file(WRITE "${out}" "${body}")
endfunction()
