-- Run by tests/editors.rs in a headless Neovim (Debian's 0.7, or newer) with editors/nvim on
-- 'runtimepath': the plugin as a user sets it up, against the real `semo lsp`.
-- Environment: SEMO_BIN (the binary), SEMO_WORKSPACE (a copy of tests/editors/workspace),
-- SEMO_SITE (where the tree-sitter parser is compiled to).
-- Each check prints one line; any failure exits with status 1 and says what was expected.

local function fail(message)
  io.stderr:write('FAILED: ' .. message .. '\n')
  vim.cmd('cquit 1')
end

local function check(condition, message)
  if not condition then
    fail(message)
  end
end

local function report(line)
  io.stdout:write(line .. '\n')
end

local function run()
  local workspace = os.getenv('SEMO_WORKSPACE')
  local site = os.getenv('SEMO_SITE')
  local semo = require('semo')

  -- The tree-sitter parser, compiled from the committed parser.c as the README says.
  semo.build_parser(site)
  vim.opt.runtimepath:prepend(site)
  semo.setup({ cmd = { os.getenv('SEMO_BIN'), 'lsp' } })

  vim.cmd('edit ' .. vim.fn.fnameescape(workspace .. '/rover.mission'))
  local buf = vim.api.nvim_get_current_buf()
  check(vim.bo[buf].filetype == 'semo', 'filetype of a .mission is ' .. vim.bo[buf].filetype)
  report('filetype: semo')

  -- 1. The diagnostic of the misspelt mode, published by the server.
  local published = vim.wait(30000, function()
    return #vim.diagnostic.get(buf) > 0
  end, 50)
  check(published, 'no diagnostics within 30 s')
  local d = vim.diagnostic.get(buf)[1]
  report(string.format('diagnostic: %d:%d %s: %s', d.lnum + 1, d.col + 1,
    tostring(d.code), d.message))
  check(d.lnum == 23 and d.col == 23, 'the diagnostic is not on `MOVNG` (line 24, column 24)')
  check(d.severity == vim.diagnostic.severity.ERROR, 'the diagnostic is not an error')
  check(d.message:find('MOVING', 1, true), 'the message does not suggest `MOVING`')

  -- 2. Tree-sitter highlighting: the highlighter runs on the mission, and the query
  -- captures `throw GO` as an exception keyword and its event.
  check(vim.treesitter.highlighter.active[buf] ~= nil,
    'the tree-sitter highlighter is not active on the mission')
  local root = vim.treesitter.get_parser(buf, 'semo'):parse()[1]:root()
  check(not root:has_error(), 'the mission does not parse without errors')
  local get_query = (vim.treesitter.query and vim.treesitter.query.get) or vim.treesitter.get_query
  local query = get_query('semo', 'highlights')
  local function captures_at(row, col)
    local names = {}
    for id, node in query:iter_captures(root, buf, row, row + 1) do
      local start_row, start_col, end_row, end_col = node:range()
      if start_row == row and end_row == row and start_col <= col and col < end_col then
        table.insert(names, '@' .. query.captures[id])
      end
    end
    return table.concat(names, ' ')
  end
  local line = vim.api.nvim_buf_get_lines(buf, 8, 9, false)[1]
  local throw_col = line:find('throw GO', 1, true) - 1
  local throw = captures_at(8, throw_col)
  local event = captures_at(8, throw_col + 6)
  report('captures at `throw GO`: ' .. throw .. ' / ' .. event)
  check(throw == '@keyword.exception', '`throw` is not captured as @keyword.exception')
  check(event == '@label', 'the event `GO` is not captured as @label')
  local team = captures_at(6, 0)
  check(team == '@module', 'the team of a service header is ' .. team)

  -- 3. Completion inside `set(Action, `: the services of plan Action, and OFF.
  vim.api.nvim_buf_set_lines(buf, 18, 19, false, { '  set(Action, ' })
  vim.api.nvim_win_set_cursor(0, { 19, 14 })
  local params = vim.lsp.util.make_position_params()
  local responses = vim.lsp.buf_request_sync(buf, 'textDocument/completion', params, 10000)
  check(responses ~= nil, 'no completion response within 10 s')
  local labels = {}
  for _, response in pairs(responses) do
    local result = response.result or {}
    for _, item in ipairs(result.items or result) do
      table.insert(labels, item.label)
    end
  end
  table.sort(labels)
  report('completion in `set(Action, `: ' .. table.concat(labels, ' '))
  check(table.concat(labels, ' ') == 'Drive OFF Wait',
    'expected the services of plan Action (Drive, Wait) and OFF')


  -- 4. Strategy, robot and task-graph files stay `xml` but get the server; other XML not.
  local function semo_clients(b)
    local clients = vim.lsp.get_clients and vim.lsp.get_clients({ bufnr = b })
      or vim.tbl_values(vim.lsp.buf_get_clients(b))
    return #vim.tbl_filter(function(c) return c.name == 'semo' end, clients)
  end
  for _, name in ipairs({ 'Rover.strategy.xml', 'beacon.robot.xml', 'loop.taskgraph.xml', 'plain.xml' }) do
    vim.cmd('edit ' .. vim.fn.fnameescape(workspace .. '/' .. name))
    local b = vim.api.nvim_get_current_buf()
    local want = name == 'plain.xml' and 0 or 1
    report(string.format('%s: filetype %s, %d semo client(s)', name, vim.bo[b].filetype, semo_clients(b)))
    check(vim.bo[b].filetype == 'xml', name .. ' is not xml')
    check(semo_clients(b) == want, name .. ': expected ' .. want .. ' semo client(s)')
  end

  -- 4b. The project file (filetype toml) gets the server, and its diagnostics: an error
  -- code cannot be allowed (E112). Other TOML files do not get the server.
  vim.fn.writefile({ '[lints]', 'E010 = "allow"' }, workspace .. '/semo.toml')
  vim.fn.writefile({ '[package]' }, workspace .. '/other.toml')
  vim.cmd('edit ' .. vim.fn.fnameescape(workspace .. '/other.toml'))
  local other = vim.api.nvim_get_current_buf()
  vim.cmd('edit ' .. vim.fn.fnameescape(workspace .. '/semo.toml'))
  local project = vim.api.nvim_get_current_buf()
  check(vim.wait(30000, function() return #vim.diagnostic.get(project) > 0 end, 50),
    'no diagnostics on semo.toml within 30 s')
  local e112 = vim.diagnostic.get(project)[1]
  report(string.format('semo.toml: filetype %s, %d semo client(s), %d:%d %s', vim.bo[project].filetype,
    semo_clients(project), e112.lnum + 1, e112.col + 1, tostring(e112.code)))
  check(e112.code == 'E112' and e112.lnum == 1 and e112.col == 7, 'expected E112 on "allow" (2:8)')
  check(semo_clients(other) == 0, 'other.toml got the semo server')
  -- Deleted, then closed: the server forgets it (what it reads is on disk no more).
  for _, name in ipairs({ 'semo.toml', 'other.toml' }) do
    vim.fn.delete(workspace .. '/' .. name)
    vim.cmd('bwipeout! ' .. vim.fn.fnameescape(workspace .. '/' .. name))
  end

  -- 5. lsp/semo.lua (for `vim.lsp.enable` on 0.11+) finds the workspace of a mission and
  -- declines plain XML.
  local spec = dofile(vim.api.nvim_get_runtime_file('lsp/semo.lua', false)[1])
  check(spec.cmd[1] == 'semo' and spec.cmd[2] == 'lsp', 'lsp/semo.lua does not run `semo lsp`')
  local roots = {}
  spec.root_dir(buf, function(dir) table.insert(roots, dir) end)
  spec.root_dir(vim.api.nvim_get_current_buf(), function(dir) table.insert(roots, dir) end)
  check(#roots == 1 and roots[1] == vim.fn.resolve(workspace), 'lsp/semo.lua root_dir gave ' .. vim.inspect(roots))
  report('lsp/semo.lua: root ' .. roots[1])

  -- 6. `:SemoSimulate`'s function on the mission with its mistake fixed: the summary, the
  -- timeline written as SVG, and the failed expectation as a diagnostic on the scenario.
  -- The empty strategy and catalog buffers of step 4 are closed first (they are errors).
  for _, name in ipairs({ 'Rover.strategy.xml', 'beacon.robot.xml', 'loop.taskgraph.xml', 'plain.xml' }) do
    vim.cmd('bwipeout! ' .. vim.fn.fnameescape(workspace .. '/' .. name))
  end
  local fixed = table.concat(vim.fn.readfile(workspace .. '/rover.mission'), '\n'):gsub('MOVNG', 'MOVING')
  vim.fn.writefile(vim.split(fixed, '\n'), workspace .. '/drive.mission')
  vim.fn.writefile({ '{"duration": 3000,',
    ' "operator": [{"at": 1000, "to": "r", "value": "RC_CMD", "is": "go"}],',
    ' "expect": [{"robot": "r", "enters": "MOVING", "before": 2500},',
    '            {"robot": "r", "never_enters": "IDLE"}]}' }, workspace .. '/drive.scenario.json')
  vim.cmd('edit ' .. vim.fn.fnameescape(workspace .. '/drive.mission'))
  local mission = vim.api.nvim_get_current_buf()
  check(vim.wait(30000, function() return semo_clients(mission) == 1 end, 50), 'drive.mission has no server')
  check(vim.fn.exists(':SemoSimulate') == 2, 'no :SemoSimulate command')
  local result
  semo.simulate(mission, nil, nil, function(err, answer) result = { err = err, answer = answer } end)
  check(vim.wait(30000, function() return result ~= nil end, 50), 'no simulation answer within 30 s')
  check(result.err == nil, 'the simulation was refused: ' .. tostring(result.err))
  local modes = result.answer.summary:match('Rover/r: ([^\n(]*)')
  report('simulate: ' .. vim.trim(modes or '?') .. ', ok ' .. tostring(result.answer.ok))
  local svg = table.concat(vim.fn.readfile(workspace .. '/drive.svg'), '\n')
  check(result.answer.svg_path == workspace .. '/drive.svg' and svg:find('<svg', 1, true) == 1,
    'the timeline was not written to drive.svg')
  local scenario = vim.uri_to_bufnr(vim.uri_from_fname(workspace .. '/drive.scenario.json'))
  check(vim.wait(10000, function() return #vim.diagnostic.get(scenario) > 0 end, 50),
    'no diagnostic on the scenario')
  local failed = vim.diagnostic.get(scenario)[1]
  report(string.format('scenario diagnostic: %d:%d %s', failed.lnum + 1, failed.col + 1, failed.message))

  -- 6b. `:SemoVerify`'s function on the same mission with a property of its own: the search's
  -- headline and the property's verdict; then the command as a user types it, which fills
  -- the quickfix list.
  vim.fn.writefile({ '{"expect": [{"eventually": {"robot": "r", "in": "MOVING"}}]}' },
    workspace .. '/drive.properties.json')
  check(vim.fn.exists(':SemoVerify') == 2, 'no :SemoVerify command')
  local verified
  semo.verify(mission, 'drive.properties.json', function(err, answer) verified = { err = err, answer = answer } end)
  check(vim.wait(60000, function() return verified ~= nil end, 50), 'no verify answer within 60 s')
  check(verified.err == nil, 'the search was refused: ' .. tostring(verified.err))
  local property = verified.answer.properties[1]
  report('verify: ' .. vim.split(verified.answer.summary, '\n')[1] .. '; ' .. property.expectation
    .. ': ' .. property.verdict)
  vim.fn.setqflist({}, ' ', { title = 'none yet', items = {} })
  vim.cmd('SemoVerify')
  check(vim.wait(60000, function() return vim.fn.getqflist({ title = 0 }).title == 'semo verify' end, 50),
    ':SemoVerify did not fill the quickfix list')
  report('verify quickfix: ' .. #vim.fn.getqflist() .. ' finding(s)')

  -- 7. `:SemoMonitor`'s function on the mission with a broker nobody listens on: every robot
  -- waiting, the connection shown down; stopping it answers that it ran.
  check(vim.fn.exists(':SemoMonitor') == 2, 'no :SemoMonitor command')
  local seen, started
  semo.monitor(mission, 'mqtt://127.0.0.1:1', function(view)
    if view.connection == 'disconnected' then seen = view end
  end, function(err, answer) started = { err = err, answer = answer } end)
  check(vim.wait(30000, function() return started ~= nil and seen ~= nil end, 50),
    'no disconnected monitor view within 30 s: ' .. vim.inspect(started))
  check(started.err == nil, 'the monitor was refused: ' .. tostring(started.err))
  report('monitor: ' .. vim.split(semo.monitor_table(seen), '\n')[2])
  local stopped
  semo.monitor_stop(mission, function(err, answer) stopped = { err = err, answer = answer } end)
  check(vim.wait(10000, function() return stopped ~= nil end, 50), 'no answer to semo/monitor/stop')
  check(stopped.answer and stopped.answer.stopped == true, 'the monitor did not run: ' .. vim.inspect(stopped))

  -- 7b. `:SemoMonitor` as a user types it: the table in a window of its own, rewritten in
  -- place, and not one notification (it once printed every table through vim.notify).
  local notified = 0
  local notify = vim.notify
  vim.notify = function(message, level)
    notified = notified + 1
    notify(message, level)
  end
  local windows = #vim.api.nvim_list_wins()
  vim.cmd('SemoMonitor mqtt://127.0.0.1:1')
  local monitor = vim.fn.bufnr('semo-monitor://drive.mission')
  check(monitor ~= -1, 'no semo-monitor://drive.mission buffer')
  check(#vim.api.nvim_list_wins() == windows + 1, 'the monitor has no window of its own')
  check(vim.api.nvim_get_current_buf() == mission, 'the monitor took the cursor from the mission')
  local function shown() return vim.api.nvim_buf_get_lines(monitor, 0, -1, false) end
  check(vim.wait(30000, function() return shown()[1]:find('disconnected', 1, true) ~= nil end, 50),
    'the monitor window never showed the disconnected table: ' .. vim.inspect(shown()))
  check(#shown() == #vim.split(semo.monitor_table(seen), '\n'),
    'the monitor window is not one table: ' .. vim.inspect(shown()))
  report('monitor window: ' .. shown()[2])
  vim.cmd('SemoMonitorStop')
  check(vim.wait(10000, function() return shown()[1]:find('(monitor stopped)', 1, true) ~= nil end, 50),
    'the monitor window does not say it stopped: ' .. vim.inspect(shown()))
  vim.notify = notify
  check(notified == 0, notified .. ' notification(s) from :SemoMonitor')

  -- 7b'. A robot's counted groups end its line; a robot without any has none.
  local grouped = semo.monitor_table({ mission = 'm', broker = 'b', connection = 'connected',
    robots = { { robot = 'tb_2', team = 'Crew', state = 'running', lost = false, mode = 'ROOMS',
      services = { { plan = 'Work', service = 'Rooms' } },
      groups = { { group = 'Room1', alive = 5 }, { group = 'others', alive = 3 } } },
      { robot = 'tb_3', team = 'Crew', state = 'running', lost = false, mode = 'ROOMS',
        services = {}, groups = {} } } })
  local grouped_lines = vim.split(grouped, '\n')
  check(grouped_lines[2]:find('Work=Rooms%s+Room1%(5%),others%(3%)$') ~= nil,
    'the groups are not at the end of the line: ' .. grouped_lines[2])
  check(grouped_lines[3] == 'tb_3       Crew         running          ROOMS',
    'a robot without groups: ' .. vim.inspect(grouped_lines[3]))
  report('monitor groups: ' .. grouped_lines[2])

  -- 7c. The running robots on the mission text: a view as the server sends it (r in MOVING,
  -- running Drive) marks the mode's line and the service's; a lost robot marks nothing.
  local lines = vim.api.nvim_buf_get_lines(mission, 0, -1, false)
  local function line_of(pattern)
    for i, text in ipairs(lines) do
      if text:find(pattern) then return i end
    end
    fail('no line matches ' .. pattern)
  end
  local mode_line, service_line = line_of('%.MOVING%s*{'), line_of('%.Drive%s*{')
  local view = { robots = { { robot = 'r', team = 'Rover', state = 'running', lost = false,
    mode = 'MOVING', modeLine = mode_line,
    services = { { plan = 'Motion', service = 'Drive', line = service_line } } } } }
  semo.monitor_marks(mission, view)
  local ns = vim.api.nvim_create_namespace('semo-monitor')
  local marks = vim.api.nvim_buf_get_extmarks(mission, ns, 0, -1, { details = true })
  check(#marks == 2, 'expected 2 marks, got ' .. vim.inspect(marks))
  local texts = {}
  for _, m in ipairs(marks) do texts[m[2] + 1] = m[4].virt_text[1][1] end
  check(texts[mode_line] == '◀ in this mode: r', 'mode mark: ' .. vim.inspect(texts))
  check(texts[service_line] == '▶ running: r', 'service mark: ' .. vim.inspect(texts))
  report('marks: ' .. texts[mode_line])
  view.robots[1].lost = true
  semo.monitor_marks(mission, view)
  check(#vim.api.nvim_buf_get_extmarks(mission, ns, 0, -1, {}) == 0, 'a lost robot is still marked')
  vim.cmd('only')

  -- 8. The scenario file (filetype json) gets the server, and completion of an expectation's
  -- mode offers the modes of its mission (drive.scenario.json belongs to drive.mission).
  vim.cmd('edit ' .. vim.fn.fnameescape(workspace .. '/drive.scenario.json'))
  local sbuf = vim.api.nvim_get_current_buf()
  check(vim.wait(30000, function() return semo_clients(sbuf) == 1 end, 50), 'the scenario has no server')
  local sline = vim.api.nvim_buf_get_lines(sbuf, 2, 3, false)[1]
  vim.api.nvim_win_set_cursor(0, { 3, sline:find('MOVING', 1, true) - 1 })
  local sresponses = vim.lsp.buf_request_sync(sbuf, 'textDocument/completion',
    vim.lsp.util.make_position_params(), 10000)
  check(sresponses ~= nil, 'no scenario completion within 10 s')
  local modes_offered = {}
  for _, response in pairs(sresponses) do
    local result = response.result or {}
    for _, item in ipairs(result.items or result) do
      table.insert(modes_offered, item.label)
    end
  end
  table.sort(modes_offered)
  report('scenario completion at `"enters": "`: ' .. table.concat(modes_offered, ' '))
  check(vim.tbl_contains(modes_offered, 'MOVING') and vim.tbl_contains(modes_offered, 'IDLE'),
    'expected the modes of drive.mission')
end

local ok, err = pcall(run)
if not ok then
  fail(tostring(err))
end
vim.cmd('qall!')
