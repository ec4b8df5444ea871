-- SeMo in Neovim 0.7 and newer: the language server (`semo lsp`) for missions and for
-- strategy, robot and task-graph XML files, and tree-sitter highlighting of missions.
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
local M = {}

-- XML files that the server reads, and scenario files it completes; their filetype stays
-- `xml` or `json`.
M.file_patterns = { '%.strategy%.xml$', '%.robot%.xml$', '%.taskgraph%.xml$', '%.scenario%.json$' }

local config = { cmd = { 'semo', 'lsp' }, treesitter = true }

--- Whether the buffer is a mission or one of the server's XML or scenario files.
function M.is_semo_buffer(bufnr)
  if vim.bo[bufnr].filetype == 'semo' then
    return true
  end
  local name = vim.api.nvim_buf_get_name(bufnr)
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
  vim.api.nvim_create_autocmd('FileType', {
    group = group,
    pattern = { 'semo', 'xml', 'json' },
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
