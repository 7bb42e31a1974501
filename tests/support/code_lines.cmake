# artcal_check_code_lines(ALLOWED CHECK): the architecture checks' walk over the project's code.
# Calls the function named CHECK as CHECK(FILE NUMBER CODE) for every line of src/, include/,
# tools/ and python/ (.cpp, .hpp) outside the files whose path (relative to SOURCE_DIR) matches
# the regular expression ALLOWED; CODE is the line without its // comment. CHECK reports with
#   set(faults "${faults}  ${file}:${number} ...\n" PARENT_SCOPE)
# and the faults come back in the caller's `faults`.
function(artcal_check_code_lines allowed check)
  file(GLOB_RECURSE files RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/src/*.cpp ${SOURCE_DIR}/src/*.hpp
       ${SOURCE_DIR}/include/*.hpp ${SOURCE_DIR}/tools/*.cpp ${SOURCE_DIR}/tools/*.hpp
       ${SOURCE_DIR}/python/*.cpp)
  set(faults "")
  foreach(file ${files})
    if(file MATCHES "${allowed}")
      continue()
    endif()
    file(STRINGS ${SOURCE_DIR}/${file} lines)
    set(number 0)
    foreach(line IN LISTS lines)
      math(EXPR number "${number} + 1")
      string(REGEX REPLACE "//.*" "" code " ${line} ")
      cmake_language(CALL ${check} "${file}" ${number} "${code}")
    endforeach()
  endforeach()
  set(faults "${faults}" PARENT_SCOPE)
endfunction()

# artcal_compared_name(CODE PATTERN OUT): OUT is the name matching PATTERN (alternatives) that
# CODE compares a string with ("name" == x, x != "name"), or "".
function(artcal_compared_name code pattern out)
  set(name "")
  if(code MATCHES "[=!]= *\"(${pattern})\"")
    set(name "${CMAKE_MATCH_1}")
  elseif(code MATCHES "\"(${pattern})\" *[=!]=")
    set(name "${CMAKE_MATCH_1}")
  endif()
  set(${out} "${name}" PARENT_SCOPE)
endfunction()

# artcal_captured(FILE REGEX OUT): appends to OUT the first group of REGEX in each line of FILE
# that matches it (the names a check reads from the code: a family's class, a kind's name).
function(artcal_captured file regex out)
  file(STRINGS ${file} lines REGEX "${regex}")
  set(values ${${out}})
  foreach(line ${lines})
    if(line MATCHES "${regex}")
      list(APPEND values "${CMAKE_MATCH_1}")
    endif()
  endforeach()
  set(${out} ${values} PARENT_SCOPE)
endfunction()
