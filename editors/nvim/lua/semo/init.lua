-- SeMo in Neovim 0.7 and newer: the language server (`semo lsp`) for missions, for
-- strategy, robot and task-graph XML files and for the project file `semo.toml`, and
-- tree-sitter highlighting of missions.
--
--   vim.opt.runtimepath:append('/path/to/semo/editors/nvim')
--   require('semo').setup()                 -- or setup({ cmd = { '/path/to/semo', 'lsp' } })
--
-- On Neovim 0.11+ `vim.lsp.enable('semo')` (lsp/semo.lua) can replace the LSP part.
--
-- `:SemoSimulate [SCENARIO [OUT.svg]]` in a mission runs it on a scenario (default: the
-- `*.scenario.json` named after the mission, beside it) through the server's `semo.simulate`,
-- shows the summary and writes the timeline SVG (default: the scenario's name, `.svg`).
-- Failed expectations appear as diagnostics on the scenario file.
--
-- `:SemoVerify [EXPECT]` in a mission explores everything its team can do through the
-- server's `semo.verify` (as `semo verify` does; EXPECT: a scenario file whose `expect` list
-- is checked over every behaviour), shows the summary and puts the findings in the quickfix
-- list.
--
-- `:SemoMonitor [BROKER]` in a mission watches its running robots on the MQTT broker (the
-- server's `semo/monitor`; default: the deployment file's broker) in a window of its own: the
-- table of robots, modes, services and leader, rewritten in place as it changes (a buffer
-- `semo-monitor://MISSION`), and marks in the mission the line of each running robot's mode
-- and services (virtual text); `:SemoMonitorStop` ends it (the last table stays, marked).
local M = {}

-- XML files that the server reads, and scenario files it completes; their filetype stays
-- `xml` or `json`.
M.file_patterns = { '%.strategy%.xml$', '%.robot%.xml$', '%.taskgraph%.xml$', '%.scenario%.json$' }

-- The project file (filetype `toml`): checked and completed by the server.
M.project_pattern = '/semo%.toml$'

local config = { cmd = { 'semo', 'lsp' }, treesitter = true }

--- Whether the buffer is a mission, one of the server's XML or scenario files, or a `semo.toml`.
function M.is_semo_buffer(bufnr)
  if vim.bo[bufnr].filetype == 'semo' then
    return true
  end
  local name = vim.api.nvim_buf_get_name(bufnr)
  if name:match(M.project_pattern) then
    return true
  end
  for _, pattern in ipairs(M.file_patterns) do
    if name:match(pattern) then
      return true
    end
  end
  return false
end

--- The workspace of a file: the nearest folder above it holding `.git`, else its folder.
function M.root_dir(fname)
  local dir = vim.fn.fnamemodify(fname, ':p:h')
  local git = vim.fn.finddir('.git', dir .. ';')
  if git == '' then
    git = vim.fn.findfile('.git', dir .. ';') -- a worktree's `.git` is a file
  end
  if git ~= '' then
    return vim.fn.fnamemodify(git, ':p:h:h')
  end
  return dir
end

-- Clients started on Neovim 0.7, by workspace folder (0.8+ `vim.lsp.start` reuses its own).
local clients = {}

--- Attaches the buffer to the server of its workspace, starting it if needed.
function M.attach(bufnr)
  local root = M.root_dir(vim.api.nvim_buf_get_name(bufnr))
  local client_config = {
    name = 'semo',
    cmd = config.cmd,
    root_dir = root,
    workspace_folders = { { uri = vim.uri_from_fname(root), name = root } },
  }
  if vim.lsp.start then
    return vim.lsp.start(client_config, { bufnr = bufnr })
  end
  local id = clients[root]
  if id == nil or vim.lsp.get_client_by_id(id) == nil then
    client_config.on_exit = function()
      clients[root] = nil
    end
    id = vim.lsp.start_client(client_config)
    if id == nil then
      vim.notify('semo: could not start ' .. table.concat(config.cmd, ' '), vim.log.levels.ERROR)
      return nil
    end
    clients[root] = id
  end
  vim.lsp.buf_attach_client(bufnr, id)
  return id
end

--- Highlights the buffer with the tree-sitter parser, if `parser/semo.so` is installed.
function M.start_treesitter(bufnr)
  local ok, parser = pcall(vim.treesitter.get_parser, bufnr, 'semo')
  if not ok or parser == nil then
    return false
  end
  if vim.treesitter.start then
    vim.treesitter.start(bufnr, 'semo')
  else
    vim.treesitter.highlighter.new(parser)
  end
  return true
end

--- This file's folder, to find the grammar beside the plugin (editors/nvim/lua/semo).
local function repo_root()
  local here = debug.getinfo(1, 'S').source:sub(2)
  return vim.fn.fnamemodify(here, ':p:h:h:h:h:h')
end

--- Compiles the grammar's generated parser (grammars/tree-sitter-semo/src/parser.c) into
--- `parser/semo.so` under `dir` (default: stdpath('data') .. '/site', on 'runtimepath').
function M.build_parser(dir)
  dir = dir or (vim.fn.stdpath('data') .. '/site')
  local src = repo_root() .. '/grammars/tree-sitter-semo/src'
  local out = dir .. '/parser/semo.so'
  vim.fn.mkdir(dir .. '/parser', 'p')
  local cc = vim.env.CC or 'cc'
  local output = vim.fn.system({ cc, '-o', out, '-shared', '-fPIC', '-O2', '-I', src, src .. '/parser.c' })
  if vim.v.shell_error ~= 0 then
    error('semo: compiling the parser failed: ' .. output)
  end
  return out
end

-- The server's own semantic token types, linked to the standard LSP groups so colour
-- schemes colour them (Neovim 0.9+ highlights a token as `@lsp.type.<type>.<filetype>`
-- and links only the standard types itself). The same types as package.json declares.
M.token_links = {
  team = '@lsp.type.namespace',
  robot = '@lsp.type.variable',
  robotType = '@lsp.type.type',
  capability = '@lsp.type.interface',
  plan = '@lsp.type.property',
  group = '@lsp.type.namespace',
  service = '@lsp.type.function',
  mode = '@lsp.type.enumMember',
  value = '@lsp.type.enumMember',
  constant = '@lsp.type.variable',
}

--- Links the token highlight groups (a colour scheme clears them, so again on each).
--- Returns false on Neovim before 0.9, which has no semantic-token highlighting.
function M.link_token_highlights()
  if vim.fn.has('nvim-0.9') == 0 then
    return false
  end
  for name, target in pairs(M.token_links) do
    vim.api.nvim_set_hl(0, '@lsp.type.' .. name .. '.semo', { link = target, default = true })
  end
  return true
end

--- The semo client attached to the buffer, if any.
local function client_of(bufnr)
  local get = vim.lsp.get_clients or vim.lsp.get_active_clients
  for _, client in ipairs(get({ bufnr = bufnr })) do
    if client.name == 'semo' then
      return client
    end
  end
  return nil
end

--- Runs the mission of `bufnr` on `scenario` (path, relative to the mission's folder) and
--- writes the timeline to `svg`; `done(err, answer)` is called with the server's answer
--- (`ok`, `summary`, `svg`, `expectations`) or the reason it refused.
function M.simulate(bufnr, scenario, svg, done)
  local mission = vim.api.nvim_buf_get_name(bufnr)
  local folder = vim.fn.fnamemodify(mission, ':p:h')
  scenario = scenario or (vim.fn.fnamemodify(mission, ':t:r') .. '.scenario.json')
  if scenario:sub(1, 1) ~= '/' then
    scenario = folder .. '/' .. scenario
  end
  svg = svg or (scenario:gsub('%.scenario%.json$', ''):gsub('%.json$', '') .. '.svg')
  local client = client_of(bufnr)
  if client == nil then
    return done('no semo server is attached to this buffer')
  end
  local params = {
    command = 'semo.simulate',
    arguments = { { uri = vim.uri_from_bufnr(bufnr), scenario = vim.uri_from_fname(scenario) } },
  }
  client.request('workspace/executeCommand', params, function(err, answer)
    if err then
      return done(err.message or tostring(err))
    end
    local file = io.open(svg, 'w')
    if file == nil then
      return done('cannot write ' .. svg)
    end
    file:write(answer.svg)
    file:close()
    answer.svg_path = svg
    done(nil, answer)
  end, bufnr)
end

--- Explores the mission of `bufnr` (`expect`: a scenario whose `expect` list is checked too,
--- relative to the mission's folder); `done(err, answer)` gets the server's answer
--- (`summary`, `findings`, `properties`, ...) or the reason it refused.
function M.verify(bufnr, expect, done)
  local client = client_of(bufnr)
  if client == nil then
    return done('no semo server is attached to this buffer')
  end
  local argument = { uri = vim.uri_from_bufnr(bufnr) }
  if expect ~= nil and expect ~= '' then
    if expect:sub(1, 1) ~= '/' then
      expect = vim.fn.fnamemodify(vim.api.nvim_buf_get_name(bufnr), ':p:h') .. '/' .. expect
    end
    argument.expect = vim.uri_from_fname(expect)
  end
  local params = { command = 'semo.verify', arguments = { argument } }
  client.request('workspace/executeCommand', params, function(err, answer)
    done(err and (err.message or tostring(err)), answer)
  end, bufnr)
end

--- The quickfix entries of a `semo.verify` answer's findings in the mission of `bufnr`.
function M.verify_quickfix(bufnr, answer)
  local items = {}
  for _, finding in ipairs(answer.findings) do
    table.insert(items, {
      bufnr = bufnr,
      lnum = finding.range.start.line + 1,
      col = finding.range.start.character + 1,
      text = finding.code .. ': ' .. finding.message,
      type = 'W',
    })
  end
  return items
end

-- The live robot monitor: the last `semo/monitor` view of each mission URI, and who wants it.
M.monitor_views = {}
local monitor_listeners = {}

-- JSON null arrives as vim.NIL or nil depending on the Neovim version.
local function present(value)
  if value == nil or value == vim.NIL then
    return nil
  end
  return value
end

--- A `semo/monitor` view (docs/live-monitor.md) as a table: a header, one line per robot
--- (`*` marks a leader; lost robots say why; counted groups last, `Room1(5),others(3)`).
function M.monitor_table(view)
  local error = present(view.error)
  local lines = {
    string.format('%s%s on %s: %s%s', view.mission,
      present(view.run) and (' (run ' .. view.run .. ')') or '', view.broker, view.connection,
      error and (' (' .. error .. ')') or ''),
  }
  for _, robot in ipairs(view.robots) do
    local services = {}
    for _, s in ipairs(robot.services) do
      table.insert(services, s.plan .. '=' .. s.service)
    end
    local groups = {}
    for _, g in ipairs(robot.groups or {}) do
      table.insert(groups, string.format('%s(%s)', g.group, tostring(g.alive)))
    end
    local state = robot.state
    if robot.lost then
      state = 'LOST (' .. (present(robot.lostBecause) or '?') .. ')'
    end
    table.insert(lines, vim.trim(string.format('%-10s %-12s %-16s %-14s %-20s %s',
      robot.robot .. (robot.isLeader and ' *' or ''), robot.team, state,
      present(robot.mode) or '', table.concat(services, ','), table.concat(groups, ','))))
  end
  return table.concat(lines, '\n')
end

--- The scratch buffer showing the monitor of mission `uri` (created, and shown in a split
--- below the current window, the first time).
function M.monitor_buffer(uri)
  local name = 'semo-monitor://' .. vim.fn.fnamemodify(vim.uri_to_fname(uri), ':t')
  local buf = vim.fn.bufnr(name)
  if buf == -1 then
    buf = vim.api.nvim_create_buf(false, true)
    vim.api.nvim_buf_set_name(buf, name)
    vim.bo[buf].buftype = 'nofile'
    vim.bo[buf].bufhidden = 'hide'
    vim.bo[buf].swapfile = false
  end
  if vim.fn.bufwinid(buf) == -1 then
    local current = vim.api.nvim_get_current_win()
    vim.cmd('belowright split')
    vim.api.nvim_win_set_buf(0, buf)
    vim.api.nvim_win_set_height(0, 8)
    vim.api.nvim_set_current_win(current)
  end
  return buf
end

local marks_namespace = vim.api.nvim_create_namespace('semo-monitor')

--- Marks in the mission buffer `bufnr` where a monitor view's running robots are: at the
--- end of each mode's line the robots in that mode, at each service's line the robots
--- running it (virtual text; the marks of the previous view are cleared first). A view
--- without lines (an older server) or nil clears them.
function M.monitor_marks(bufnr, view)
  vim.api.nvim_buf_clear_namespace(bufnr, marks_namespace, 0, -1)
  if view == nil then
    return
  end
  local marks, order = {}, {}
  local function add(line, kind, robot)
    line = present(line)
    if type(line) ~= 'number' or line < 1 or line > vim.api.nvim_buf_line_count(bufnr) then
      return
    end
    local key = kind .. ':' .. line
    if marks[key] == nil then
      marks[key] = { line = line, kind = kind, robots = {} }
      table.insert(order, key)
    end
    table.insert(marks[key].robots, robot)
  end
  for _, robot in ipairs(view.robots) do
    if not robot.lost and robot.state ~= 'waiting' then
      add(robot.modeLine, 'mode', robot.robot)
      for _, s in ipairs(robot.services) do
        add(s.line, 'service', robot.robot)
      end
    end
  end
  for _, key in ipairs(order) do
    local mark = marks[key]
    local text = (mark.kind == 'mode' and '◀ in this mode: ' or '▶ running: ')
      .. table.concat(mark.robots, ', ')
    vim.api.nvim_buf_set_extmark(bufnr, marks_namespace, mark.line - 1, 0, {
      virt_text = { { text, mark.kind == 'mode' and 'DiagnosticInfo' or 'Comment' } },
    })
  end
end

--- Shows `text` (lines) in the monitor buffer `buf`, replacing what it showed.
function M.monitor_show(buf, text)
  vim.bo[buf].modifiable = true
  vim.api.nvim_buf_set_lines(buf, 0, -1, false, vim.split(text, '\n'))
  vim.bo[buf].modifiable = false
end

local function on_monitor_view(_, view)
  if type(view) ~= 'table' or view.uri == nil then
    return
  end
  M.monitor_views[view.uri] = view
  local listener = monitor_listeners[view.uri]
  if listener then
    listener(view)
  end
end

--- Starts the server's monitor of the mission in `bufnr` (`semo/monitor/start`); `broker`
--- nil means the deployment file's, else mqtt://127.0.0.1:1883. `on_view(view)` gets every
--- `semo/monitor` notification; `done(err, answer)` the answer or why it was refused.
function M.monitor(bufnr, broker, on_view, done)
  local client = client_of(bufnr)
  if client == nil then
    return done('no semo server is attached to this buffer')
  end
  local uri = vim.uri_from_bufnr(bufnr)
  monitor_listeners[uri] = on_view
  client.request('semo/monitor/start', { uri = uri, broker = broker }, function(err, answer)
    if err then
      monitor_listeners[uri] = nil
      return done(err.message or tostring(err))
    end
    done(nil, answer)
  end, bufnr)
end

--- Ends the monitor of the mission in `bufnr`; `done(err, answer)` (`answer.stopped`).
function M.monitor_stop(bufnr, done)
  local uri = vim.uri_from_bufnr(bufnr)
  monitor_listeners[uri] = nil
  M.monitor_views[uri] = nil
  local client = client_of(bufnr)
  if client == nil then
    return done('no semo server is attached to this buffer')
  end
  client.request('semo/monitor/stop', { uri = uri }, function(err, answer)
    done(err and (err.message or tostring(err)), answer)
  end, bufnr)
end

function M.setup(opts)
  config = vim.tbl_extend('force', config, opts or {})
  local group = vim.api.nvim_create_augroup('semo', { clear = true })
  M.link_token_highlights()
  vim.api.nvim_create_autocmd('ColorScheme', { group = group, callback = M.link_token_highlights })
  vim.api.nvim_create_user_command('SemoSimulate', function(command)
    local args = command.fargs
    M.simulate(vim.api.nvim_get_current_buf(), args[1], args[2], function(err, answer)
      vim.schedule(function()
        if err then
          vim.notify('semo: ' .. err, vim.log.levels.ERROR)
        else
          vim.notify(answer.summary .. 'timeline: ' .. answer.svg_path,
            answer.ok and vim.log.levels.INFO or vim.log.levels.WARN)
        end
      end)
    end)
  end, { nargs = '*', complete = 'file', desc = 'Simulate the mission on a scenario (semo.simulate)' })
  vim.api.nvim_create_user_command('SemoVerify', function(command)
    local mission = vim.api.nvim_get_current_buf()
    vim.notify('semo: verifying…', vim.log.levels.INFO)
    M.verify(mission, command.fargs[1], function(err, answer)
      vim.schedule(function()
        if err then
          vim.notify('semo: ' .. err, vim.log.levels.ERROR)
          return
        end
        local items = M.verify_quickfix(mission, answer)
        vim.fn.setqflist({}, ' ', { title = 'semo verify', items = items })
        local broken = false
        for _, property in ipairs(answer.properties) do
          broken = broken or property.verdict == 'broken'
        end
        vim.notify(answer.summary, (#items > 0 or broken) and vim.log.levels.WARN or vim.log.levels.INFO)
      end)
    end)
  end, { nargs = '?', complete = 'file', desc = 'Explore everything the mission can do (semo.verify)' })
  vim.lsp.handlers['semo/monitor'] = on_monitor_view
  vim.api.nvim_create_user_command('SemoMonitor', function(command)
    local broker = command.fargs[1]
    local mission = vim.api.nvim_get_current_buf()
    local buf = M.monitor_buffer(vim.uri_from_bufnr(mission))
    M.monitor_show(buf, 'connecting…')
    M.monitor(mission, broker, function(view)
      vim.schedule(function()
        if vim.api.nvim_buf_is_valid(buf) then
          M.monitor_show(buf, M.monitor_table(view))
        end
        if vim.api.nvim_buf_is_valid(mission) then
          M.monitor_marks(mission, view)
        end
      end)
    end, function(err)
      if err then
        vim.schedule(function() vim.notify('semo: ' .. err, vim.log.levels.ERROR) end)
      end
    end)
  end, { nargs = '?', desc = 'Show the live status of the mission\'s robots (semo/monitor)' })
  vim.api.nvim_create_user_command('SemoMonitorStop', function()
    local mission = vim.api.nvim_get_current_buf()
    local buf = vim.fn.bufnr('semo-monitor://' .. vim.fn.expand('%:t'))
    M.monitor_stop(mission, function()
      vim.schedule(function()
        if vim.api.nvim_buf_is_valid(mission) then
          M.monitor_marks(mission, nil)
        end
        if buf ~= -1 and vim.api.nvim_buf_is_valid(buf) then
          local lines = vim.api.nvim_buf_get_lines(buf, 0, -1, false)
          lines[1] = (lines[1] or '') .. ' (monitor stopped)'
          M.monitor_show(buf, table.concat(lines, '\n'))
        end
      end)
    end)
  end, { desc = 'Stop monitoring the mission\'s robots' })
  vim.api.nvim_create_autocmd('FileType', {
    group = group,
    pattern = { 'semo', 'xml', 'json', 'toml' },
    callback = function(args)
      if not M.is_semo_buffer(args.buf) then
        return
      end
      if config.cmd then
        M.attach(args.buf)
      end
      if config.treesitter and vim.bo[args.buf].filetype == 'semo' then
        M.start_treesitter(args.buf)
      end
    end,
  })
end

return M
