/**
 * @file Tree-sitter grammar for SeMo mission scripts (`.mission`).
 *
 * It follows the mission language reference (section 2, the grammar) and the
 * compiler's own lexer and parser (compiler/src/syntax/token.rs, parser.rs), which are the
 * ground truth: where the two differ, this grammar accepts what the compiler accepts.
 */

/// <reference types="tree-sitter-cli/dsl" />
// @ts-check

const WORD = /[A-Za-z_][A-Za-z0-9_]*/;

/** `rule (, rule)*` */
function commaSep1(rule) {
  return seq(rule, repeat(seq(',', rule)));
}

/** `(rule (, rule)*)?` */
function commaSep(rule) {
  return optional(commaSep1(rule));
}

module.exports = grammar({
  name: 'semo',

  extras: $ => [/\s/, $.comment],

  // Keywords are reserved (the compiler never reads them as names), and keyword extraction
  // keeps `mainx` an identifier rather than `main` + `x`.
  word: $ => $.identifier,

  rules: {
    source_file: $ => repeat($._item),

    _item: $ => choice(
      $.formation,
      $.team_declaration,
      $.function_definition,
      $.service_definition,
      $.mode_definition,
      $.main_definition,
      ';',
    ),

    // ----- formation -----

    formation: $ => seq('{', repeat($.team_declaration), '}'),

    // Its own `;`s belong to it, not to the items after it.
    team_declaration: $ => prec.right(seq(
      field('name', $.identifier),
      ':',
      commaSep1($.robot_declaration),
      repeat(';'),
    )),

    robot_declaration: $ => seq(
      field('type', $.identifier),
      field('name', $.identifier),
      optional(seq('[', field('count', $.number), ']')),
    ),

    // ----- items -----

    service_definition: $ => seq(
      // `A, B.Plan.S`: a service each of these teams runs.
      commaSep1(field('team', $.identifier)),
      '.',
      field('plan', $.identifier),
      '.',
      field('name', $.identifier),
      optional(field('parameters', $.parameter_list)),
      field('body', $.block),
      optional(field('repeat', $.repeat_clause)),
    ),

    repeat_clause: $ => seq('repeat', '(', optional($._period_and_condition), ')'),

    function_definition: $ => seq(
      'def',
      field('name', $.identifier),
      optional(field('parameters', $.parameter_list)),
      field('body', $.block),
    ),

    // `(PLACE, WAIT)`: names that stand for the call's arguments in the body
    // (a function's), for the arguments a mode's `set` gives (a service's),
    // or for those the mode is entered with (a mode's).
    parameter_list: $ => seq('(', commaSep(field('parameter', $.identifier)), ')'),

    mode_definition: $ => seq(
      field('team', $.identifier),
      '.',
      field('name', $.identifier),
      optional(field('parameters', $.parameter_list)),
      field('body', $.mode_body),
    ),

    mode_body: $ => seq('{', repeat(choice($.set_statement, ';')), '}'),

    set_statement: $ => seq(
      'set',
      '(',
      field('plan', $.identifier),
      ',',
      field('service', choice($.identifier, $.off)),
      optional(field('arguments', $.arguments)),
      optional(seq(',', $.timeout)),
      ')',
    ),

    off: _ => 'OFF',

    main_definition: $ => seq(
      field('team', $.identifier),
      '.',
      'main',
      field('body', $.main_body),
    ),

    main_body: $ => seq('{', repeat(choice($.case_clause, $.default_clause)), '}'),

    case_clause: $ => seq(
      'case',
      '(',
      field('mode', $.identifier),
      ')',
      ':',
      repeat($.catch_clause),
    ),

    catch_clause: $ => seq(
      'catch',
      '(',
      field('event', $.identifier),
      ')',
      ':',
      $.mode_assignment,
    ),

    default_clause: $ => seq('default', ':', $.mode_assignment),

    mode_assignment: $ => seq(
      'mode',
      '=',
      field('mode', $.identifier),
      optional(field('arguments', $.arguments)),
      repeat(';'),
    ),

    // ----- statements -----

    block: $ => seq('{', repeat(choice($._statement, ';')), '}'),

    /** Braces are optional around a single statement. */
    _body: $ => choice($.block, $._statement),

    _statement: $ => choice(
      $.if_statement,
      $.loop_statement,
      $.group_statement,
      $.communication,
      $.throw_statement,
      $.call,
    ),

    if_statement: $ => prec.right(seq(
      'if',
      '(',
      field('condition', $._expression),
      ')',
      field('consequence', $._body),
      optional(seq('else', field('alternative', $._body))),
    )),

    loop_statement: $ => seq(
      'loop',
      '(',
      $._period_and_condition,
      ')',
      field('body', $._body),
    ),

    /** `(2 SEC)`, `(2 SEC, cond)` or `(cond)`: a lone period is the period, not a condition. */
    _period_and_condition: $ => choice(
      prec(1, seq(
        field('period', $.period),
        optional(seq(',', field('condition', $._expression))),
      )),
      field('condition', $._expression),
    ),

    throw_statement: $ => seq(
      'throw',
      field('event', $.identifier),
      optional(field('broadcast', 'broadcast')),
    ),

    call: $ => seq(
      optional(field('results', $.results)),
      field('function', $.identifier),
      field('arguments', $.arguments),
      optional(seq(',', $.timeout)),
    ),

    /** `FOUND, WHERE =` before a call: the names bound to its service's results. */
    results: $ => seq(commaSep1(field('name', $.identifier)), '='),

    arguments: $ => seq('(', commaSep(choice($._expression, $.words)), ')'),

    /**
     * Several bare words (names or keywords) form one string: `move(Paris palace of
     * congress)`. One token, so that as in the compiler two words or more are always a
     * string (`move(x or y)`), and one word is a value.
     */
    words: _ => token(seq(WORD, repeat1(seq(/\s+/, WORD)))),

    communication: $ => seq(
      field('kind', choice('send', 'receive', 'publish', 'subscribe')),
      '(',
      field('team', $.identifier),
      ',',
      commaSep1($.message),
      ')',
      optional(seq(',', $.timeout)),
    ),

    /** A value sent or received, or a team variable set and sent: `T.Alarm = DARK`. */
    message: $ => seq(
      field('name', $.attribute),
      optional(seq('=', field('value', $._expression))),
    ),

    group_statement: $ => seq(
      '[[',
      repeat1(choice($.group_arm, $.leader_arm)),
      optional($.others_arm),
      ']]',
    ),

    group_arm: $ => seq('group', $._group_condition, field('body', $._body)),

    leader_arm: $ => seq('leader', $._group_condition, field('body', $._body)),

    others_arm: $ => seq('others', field('body', $._body)),

    _group_condition: $ => seq(
      '(',
      field('condition', choice($.instance_of, $.capable_of, $.counted_group)),
      ')',
    ),

    instance_of: $ => seq('instance', 'of', commaSep1(field('type', $.identifier))),

    capable_of: $ => seq('capable', 'of', commaSep1(field('capability', $.identifier))),

    /** `Room1, min = 2`: a group of at least two robots chosen at run time (`min` is a word only here). */
    counted_group: $ => seq(field('name', $.identifier), ',', 'min', '=', field('min', $.number)),

    timeout: $ => seq('timeout', '=', field('period', $.period)),

    // ----- expressions (loosest first, as in the compiler) -----

    _expression: $ => choice($.or_expression, $._and_level),

    or_expression: $ => seq(
      field('left', $._expression),
      field('operator', choice('or', '||')),
      field('right', $._and_level),
    ),

    _and_level: $ => choice($.and_expression, $._not_level),

    and_expression: $ => seq(
      field('left', $._and_level),
      field('operator', choice('and', '&&')),
      field('right', $._not_level),
    ),

    _not_level: $ => choice($.not_expression, $._comparison_level),

    not_expression: $ => seq(field('operator', choice('not', '!')), field('operand', $._not_level)),

    _comparison_level: $ => choice($.comparison, $._primary),

    /** Comparisons do not chain: `a < b < c` is an error. */
    comparison: $ => seq(
      field('left', $._primary),
      field('operator', choice('==', '!=', '<', '<=', '>', '>=')),
      field('right', $._primary),
    ),

    _primary: $ => choice(
      $.string,
      $.period,
      $.number,
      $.boolean,
      $.attribute,
      $.parenthesized_expression,
    ),

    parenthesized_expression: $ => seq('(', $._expression, ')'),

    /** `LOCATION`, `SlaveTeam.COLOR`, `USER.RC_CMD`. */
    attribute: $ => seq($.identifier, repeat(seq('.', $.identifier))),

    boolean: _ => choice('true', 'false'),

    // ----- tokens -----

    /** A number followed by a time unit (units are case-insensitive and not reserved). */
    period: $ => seq(field('amount', $.number), field('unit', $.time_unit)),

    time_unit: _ => token(choice(/[mM][sS][eE][cC]/, /[sS][eE][cC]/, /[mM][iI][nN]/, /[hH][oO][uU][rR]/)),

    number: _ => token(/-?[0-9]+(\.[0-9]+)?/),

    string: _ => token(seq('"', repeat(choice(/[^"\\\n]/, /\\[^\n]/)), '"')),

    identifier: _ => WORD,

    comment: _ => token(seq('#', /[^\n]*/)),
  },
});
