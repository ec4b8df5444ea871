; Names in a mission are global (teams, services, modes, functions), so the file is the one
; scope; definitions let an editor jump from a use to the place that declares it.

(source_file) @local.scope

(team_declaration
  name: (identifier) @local.definition.namespace)

(robot_declaration
  name: (identifier) @local.definition.var)

(function_definition
  name: (identifier) @local.definition.function)

(mode_definition
  name: (identifier) @local.definition.constant)

(identifier) @local.reference
