; Highlights for SeMo missions. Capture names follow nvim-treesitter's conventions; where two
; patterns capture the same node the later one wins, so general patterns come first.

(comment) @comment

(string) @string

(words) @string

(number) @number

(time_unit) @type.builtin

(boolean) @boolean

(off) @constant.builtin

; ----- keywords -----

[
  "if"
  "else"
] @keyword.conditional

[
  "loop"
  "repeat"
] @keyword.repeat

[
  "throw"
  "broadcast"
  "catch"
] @keyword.exception

[
  "case"
  "default"
] @keyword.conditional

"def" @keyword.function

[
  "main"
  "mode"
  "set"
  "timeout"
  "group"
  "leader"
  "others"
  "instance"
  "capable"
  "of"
  "min"
] @keyword

[
  "send"
  "receive"
  "publish"
  "subscribe"
] @function.builtin

[
  "and"
  "or"
  "not"
] @keyword.operator

; ----- operators and punctuation -----

[
  "=="
  "!="
  "<"
  "<="
  ">"
  ">="
  "&&"
  "||"
  "!"
  "="
] @operator

[
  "("
  ")"
  "{"
  "}"
  "["
  "]"
] @punctuation.bracket

[
  "[["
  "]]"
] @punctuation.special

[
  ","
  ";"
  ":"
  "."
] @punctuation.delimiter

; ----- names, by the place that gives them their meaning -----

(team_declaration
  name: (identifier) @module)

(robot_declaration
  type: (identifier) @type
  name: (identifier) @variable)

(service_definition
  team: (identifier) @module
  plan: (identifier) @type
  name: (identifier) @function)

(function_definition
  name: (identifier) @function)

(parameter_list
  parameter: (identifier) @variable.parameter)

(call
  function: (identifier) @function.call)

(results
  name: (identifier) @variable)

(mode_definition
  team: (identifier) @module
  name: (identifier) @constant)

(set_statement
  plan: (identifier) @type)

(set_statement
  service: (identifier) @function)

(main_definition
  team: (identifier) @module)

(case_clause
  mode: (identifier) @constant)

(mode_assignment
  mode: (identifier) @constant)

(catch_clause
  event: (identifier) @label)

(throw_statement
  event: (identifier) @label)

(communication
  team: (identifier) @module)

(instance_of
  type: (identifier) @type)

(capable_of
  capability: (identifier) @attribute)

(counted_group
  name: (identifier) @label)

; `Team.VALUE`: a value (of the team named first); a bare `VALUE` is the robot's own.
(attribute
  (identifier) @variable.member)

(attribute
  .
  (identifier) @module
  (identifier))

; The operator's console, a predefined team.
((identifier) @constant.builtin
  (#any-of? @constant.builtin "USER" "user"))
