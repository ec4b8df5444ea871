//! The formatter's behaviour in small cases. Whole files, construct by
//! construct, are the fixtures of `tests/fixtures/format/`.

use super::*;
use crate::diag::Code;

fn fmt(text: &str) -> String {
    let out = format_source(text).unwrap_or_else(|e| panic!("refused: {e}\n{text}"));
    let again = format_source(&out).unwrap_or_else(|e| panic!("output refused: {e}\n{out}"));
    assert_eq!(again, out, "formatting is not idempotent");
    out
}

#[test]
fn a_one_line_mission_gets_the_canonical_layout() {
    assert_eq!(
        fmt(
            "{T:iRobotCreate a} T.Action.Go{move(\"5,5\");stop()}repeat(2 SEC) \
             T.GO{set(Action,Go)} T.main{default:mode=GO}"
        ),
        "{\n  T: iRobotCreate a\n}\n\nT.Action.Go {\n  move(\"5,5\");\n  stop()\n} repeat(2 SEC)\n\n\
         T.GO {\n  set(Action, Go)\n}\n\nT.main {\n  default: mode = GO\n}\n"
    );
}

#[test]
fn nothing_but_whitespace_or_comments() {
    assert_eq!(fmt(""), "");
    assert_eq!(fmt(" \n\n\t\n"), "");
    assert_eq!(
        fmt("\n\n  # only a comment   \n\n\n#another\n"),
        "# only a comment\n\n#another\n"
    );
}

#[test]
fn syntax_errors_are_refused_with_the_parser_diagnostics() {
    let text = "T.Action.Go { move(\"1,1\" }\nT.GO { set(Action Go) }\n";
    let Err(FormatRefusal::SyntaxErrors(diags)) = format_source(text) else {
        panic!("not refused");
    };
    assert_eq!(diags.len(), 2);
    assert!(diags.iter().all(|d| d.code == Code::SyntaxError));
    let refusal = FormatRefusal::SyntaxErrors(diags);
    assert_eq!(refusal.span().map(|s| s.start), text.find('('));
    assert_eq!(
        refusal.to_string(),
        "2 syntax errors, the first: this `(` is never closed"
    );
}

#[test]
fn lexical_errors_are_refused() {
    for text in [
        "T.A.S { move(\"open) }",
        "T.A.S { move(5 % 2) }",
        "\u{feff}{ T: A a }",
    ] {
        assert!(
            matches!(format_source(text), Err(FormatRefusal::SyntaxErrors(_))),
            "{text:?}"
        );
    }
}

#[test]
fn end_of_line_comments_stay_at_the_end_of_their_line() {
    assert_eq!(
        fmt("T.A.S { # body\n move(a) # go\n stop() } # done\nrepeat() # again"),
        "T.A.S { # body\n  move(a) # go\n  stop()\n} # done\n  repeat() # again\n"
    );
}

#[test]
fn own_line_comments_are_indented_like_the_code_after_them() {
    assert_eq!(
        fmt("T.A.S {\n# first\nmove(a)\n        # last\n}\n"),
        "T.A.S {\n  # first\n  move(a)\n  # last\n}\n"
    );
}

#[test]
fn a_comment_inside_a_statement_breaks_it_without_moving() {
    // Inside parentheses: they break, one part per line.
    assert_eq!(
        fmt("T.A.S { send(USER, # who\n T.X) }"),
        "T.A.S {\n  send(\n    USER, # who\n    T.X\n  )\n}\n"
    );
    // Where the layout has no break: the rest continues one level deeper.
    assert_eq!(
        fmt("T.A # plan\n.S { stop() }"),
        "T.A # plan\n  .S {\n  stop()\n}\n"
    );
}

#[test]
fn a_comment_before_else_or_repeat_puts_it_on_its_own_line() {
    assert_eq!(
        fmt("T.A.S { if(a) { x() }\n # otherwise\n else { y() } }"),
        "T.A.S {\n  if(a) {\n    x()\n  }\n  # otherwise\n  else {\n    y()\n  }\n}\n"
    );
    assert_eq!(
        fmt("T.A.S { move(a) }\n    # why\n    repeat()"),
        "T.A.S {\n  move(a)\n}\n# why\nrepeat()\n"
    );
}

#[test]
fn blank_lines_inside_blocks_are_kept_once_but_not_after_an_opener_or_before_a_closer() {
    assert_eq!(
        fmt("T.A.S {\n\n\n  a()\n\n\n\n  b()\n  c()\n\n}\n"),
        "T.A.S {\n  a()\n\n  b()\n  c()\n}\n"
    );
}

#[test]
fn items_are_separated_by_one_blank_line_but_bare_teams_stay_together() {
    assert_eq!(
        fmt("A: x a\nB: y b\n\n\nC: z c\ndef f { stop() }\n\n\n\ndef g { stop() }"),
        "A: x a\nB: y b\n\nC: z c\n\ndef f {\n  stop()\n}\n\ndef g {\n  stop()\n}\n"
    );
}

#[test]
fn tokens_keep_their_spelling() {
    let out = fmt("T.A.S { if(a||b&&!c or not d){ loop(2 sec) x() } }");
    assert!(
        out.contains("if(a || b && !c or not d) {") && out.contains("loop(2 sec)"),
        "{out}"
    );
}

#[test]
fn long_statements_break_their_parentheses_then_their_conditions() {
    let name = "A_RATHER_LONG_VALUE_NAME";
    let text = format!("T.A.S {{ send(USER, T.{name}_1, T.{name}_2, T.{name}_3, T.{name}_4) }}");
    assert_eq!(
        fmt(&text),
        format!(
            "T.A.S {{\n  send(\n    USER,\n    T.{name}_1,\n    T.{name}_2,\n    T.{name}_3,\n    \
             T.{name}_4\n  )\n}}\n"
        )
    );
    let text = format!(
        "T.A.S {{ if(T.{name}_1 == 1 and (T.{name}_2 == 2 or T.{name}_3 == 3) or T.{name}_4) stop() }}"
    );
    assert_eq!(
        fmt(&text),
        format!(
            "T.A.S {{\n  if(\n    T.{name}_1 == 1\n    and (T.{name}_2 == 2 or T.{name}_3 == 3)\n    \
             or T.{name}_4\n  )\n    stop()\n}}\n"
        )
    );
}

#[test]
fn width_counts_characters_not_bytes() {
    // 90 Korean characters are 270 bytes but fit in 100 columns.
    let text = format!("T.A.S {{ say(\"{}\") }}", "한".repeat(90));
    assert_eq!(
        fmt(&text).lines().nth(1).map(|l| l.chars().count()),
        Some(99)
    );
}

#[test]
fn crlf_files_stay_crlf() {
    assert_eq!(
        fmt("T.A.S {\r\n  move(a) # go \r\n}\r\n"),
        "T.A.S {\r\n  move(a) # go\r\n}\r\n"
    );
    assert_eq!(fmt("T.A.S {\n  move(a)\r\n}"), "T.A.S {\n  move(a)\n}\n");
}

#[test]
fn tabs_and_unusual_spaces_are_whitespace() {
    assert_eq!(
        fmt("T.A.S\t{\u{a0}move(a)\u{2003}}"),
        "T.A.S {\n  move(a)\n}\n"
    );
}

#[test]
fn unbraced_nesting_too_deep_is_refused_not_overflowed() {
    let text = format!(
        "T.A.S {{ {} stop() }}",
        "if(x) ".repeat(layout::MAX_NESTING + 1)
    );
    assert!(matches!(
        format_source(&text),
        Err(FormatRefusal::TooDeep(_))
    ));
    let text = format!(
        "T.A.S {{ {} stop() }}",
        "if(x) ".repeat(layout::MAX_NESTING - 1)
    );
    assert!(format_source(&text).is_ok());
}

#[test]
fn long_expression_chains_need_no_recursion() {
    // Within the parser's depth bound (`syntax::MAX_DEPTH` counts chained
    // logical operators too), a long chain formats and breaks.
    let text = format!(
        "T.A.S {{ if({} x {}) stop() }}",
        "not ".repeat(30),
        "and y ".repeat(30)
    );
    let out = fmt(&text);
    assert!(out.contains("\n    and y\n"), "the chain breaks");
    // Beyond it the text is refused as too deeply nested, without a panic.
    let deep = format!(
        "T.A.S {{ if({} x {}) stop() }}",
        "not ".repeat(5000),
        "and y ".repeat(5000)
    );
    assert!(matches!(
        format_source(&deep),
        Err(FormatRefusal::SyntaxErrors(_))
    ));
}

#[test]
fn a_broadcast_throw_keeps_its_keyword_on_the_statement() {
    assert_eq!(
        fmt(
            "{T:iRobotCreate a[2]} T.A.S{throw   go\n   broadcast;if(DISTANCE<5)throw near broadcast}repeat()"
        ),
        "{\n  T: iRobotCreate a[2]\n}\n\nT.A.S {\n  throw go broadcast;\n  if(DISTANCE < 5)\n    throw near broadcast\n} repeat()\n"
    );
}

#[test]
fn a_counted_group_is_written_name_comma_min_equals() {
    assert_eq!(
        fmt(
            "{T:iRobotCreate a[3]} T.A.S{[[group(  R1 ,min=2){x()}group(R2,min   = 1){y()}]]}repeat()"
        ),
        "{\n  T: iRobotCreate a[3]\n}\n\nT.A.S {\n  [[\n    group(R1, min = 2) {\n      x()\n    }\n    group(R2, min = 1) {\n      y()\n    }\n  ]]\n} repeat()\n"
    );
}

#[test]
fn a_function_keeps_its_parameter_list_on_its_header() {
    assert_eq!(
        fmt("def go_to (  PLACE ,WAIT ){move(PLACE)} def home(){stop()}"),
        "def go_to(PLACE, WAIT) {\n  move(PLACE)\n}\n\ndef home() {\n  stop()\n}\n"
    );
}

#[test]
fn a_service_shared_by_teams_lists_its_teams_on_its_header() {
    assert_eq!(
        fmt("A ,B  ,C.P.S{x()}repeat()"),
        "A, B, C.P.S {\n  x()\n} repeat()\n"
    );
}

#[test]
fn modes_and_services_keep_their_parameters_and_arguments_on_one_line() {
    assert_eq!(
        fmt(
            "R.Action.Go( PLACE,WAIT ){move(PLACE)} repeat()\nR.MOVE( TARGET ){ set(Action,Go( TARGET ,2)) }\nR.main{ case(MOVE): catch(x): mode=MOVE( hall door )\n default: mode = MOVE( kitchen ) }"
        ),
        "R.Action.Go(PLACE, WAIT) {\n  move(PLACE)\n} repeat()\n\nR.MOVE(TARGET) {\n  set(Action, Go(TARGET, 2))\n}\n\nR.main {\n  case (MOVE):\n    catch (x): mode = MOVE(hall door)\n  default: mode = MOVE(kitchen)\n}\n"
    );
}

#[test]
fn a_call_keeps_the_names_bound_to_its_results_on_its_line() {
    assert_eq!(
        fmt("T.P.S{FOUND ,WHERE=search( red paper ),timeout=2 SEC\nA=search()}"),
        "T.P.S {\n  FOUND, WHERE = search(red paper), timeout = 2 SEC\n  A = search()\n}\n"
    );
}
