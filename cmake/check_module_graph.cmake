# cmake -DGRAPH=<build>/module_graph.txt -DREADME=README.md -P check_module_graph.cmake
#
# Fails unless the lines between "<!-- module-graph:begin -->" and "<!-- module-graph:end -->" of
# the README (inside a fenced block) are, apart from the fence and blank lines, the lines of GRAPH,
# which finecap_write_module_graph wrote from what the targets really link.
file(READ ${GRAPH} graph)
file(READ ${README} readme)
string(FIND "${readme}" "<!-- module-graph:begin -->" begin)
string(FIND "${readme}" "<!-- module-graph:end -->" end)
if(begin EQUAL -1 OR end EQUAL -1 OR end LESS begin)
  message(FATAL_ERROR "${README}: no block between <!-- module-graph:begin --> and "
    "<!-- module-graph:end -->")
endif()
math(EXPR length "${end} - ${begin}")
string(SUBSTRING "${readme}" ${begin} ${length} block)
string(REPLACE "\n" ";" block_lines "${block}")
set(drawn "")
foreach(line ${block_lines})
  string(STRIP "${line}" line)
  if(line STREQUAL "" OR line MATCHES "^```" OR line MATCHES "^<!--")
    continue()
  endif()
  string(APPEND drawn "${line}\n")
endforeach()
if(NOT drawn STREQUAL graph)
  message(FATAL_ERROR "${README}: the module graph it lists is\n${drawn}\nbut the CMake targets "
    "link\n${graph}\nUpdate the README's block (between the module-graph markers) to the second.")
endif()
message(STATUS "module graph of ${README} matches the targets:\n${graph}")
