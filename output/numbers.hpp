// Numbers in sentences for people (the diagnosis' reasons, what limits a prediction): one
// format everywhere, so that the same value reads the same in the console, the report and
// diagnosis.json's reasons.
#pragma once
#include <string>

namespace quadgen::output {

// Three significant digits ("0.0524", "1.32e-06", "208").
std::string short_number(double v);
// A fraction as per cent in a sentence, three significant digits ("3.4 %", "70 %").
std::string percent_text(double fraction);
// A p-value in a sentence, "p = 0.00288", or "p < 1e-300" where it is below what a double
// holds well (a likelihood-ratio statistic of thousands on a real flight gives 0, and "p = 0"
// claims certainty no test gives); and the same without "p" for a table's cell.
std::string p_is(double p);
std::string p_value_cell(double p);
// Six significant digits ("0.265851", "1.7e+308"): where a reader adds numbers up by eye (a
// weight beside the thrusts that carry it), and never hundreds of digits.
std::string six_digits(double v);
// The shortest text that reads back as the same double (std::to_chars: "100", "0.1",
// "1e+22"): where a value differs from the one it is compared with only beyond
// six ("-1.0000000000000002" below a bound of -1), and where a file is read again (a fitted
// 0.05 is "0.05", not "0.050000000000000003").
std::string full_number(double v);
// "a then b" with six significant digits, or as many more as tell them apart: a log whose time
// goes back by a microsecond at 0.5 s read "0.500000 then 0.500000" (a review, helper-88).
// `separator` between them: " then " in a sentence, " -> " in a list of changes.
std::string one_then_other(double a, double b, const std::string& separator = " then ");
// Equal to 1e-12 relative, not bit for bit: the same value carried through another path (a
// file's number read again, a header compiled where a*b+c is contracted) may differ in its
// last bits. Not equal where either is NaN.
bool equal_but_for_rounding(double a, double b);
// A unit as a person reads it: every power raised ("kg m^2" -> "kg m²", "s^-1" -> "s⁻¹"); a
// '^' not followed by digits is kept ("R^T"). For sentences, tables and plot axes (the SVG;
// the CSV beside it keeps the label as declared). The fields a program reads keep the unit as
// declared, which is also what a user writes in a vehicle file or a mapping: every `unit` of
// diagnosis.json and model.json, the CSVs, a YAML snippet to paste. diagnosis.json's texts
// (reasons, verdicts, headlines, values in words) are the report's sentences and read as it does.
std::string unit_for_reading(const std::string& unit);
// What follows a number in a sentence: " m/s²" for a unit (read as above), nothing for a
// dimensionless one ("1", as the symbols declare it, or none), so that "motor_gain.A = 0.08"
// never reads "0.08 1".
std::string unit_after_number(const std::string& unit);

// Reading a number from text: one rule for the vehicle file, the log cells and the command
// line (three readers once judged text each their own way: 1e-400 was refused in a vehicle
// file and read as 0 from the command line and a log).
enum class NumberText {
  finite,        // a finite decimal number, the whole text
  not_a_number,  // no number, trailing text, or hexadecimal ("0x10")
  not_finite,    // inf, nan or beyond a double's range (1e400)
  underflow,     // a number too small for a double, which would read as 0 (1e-400)
};
// strtod takes its decimal point from the C locale: quadgen never calls setlocale, and must not
// (a "1.5" would read as 1 under a German locale, and the files would be misread, not refused).
// Reads the whole of `text` (blanks before it allowed, as strtod allows them) into `value`,
// which is set only when the text is a finite number. Hexadecimal is refused: strtod reads
// "0x1p3" as 8, which no log or vehicle file means.
NumberText read_number(const std::string& text, double* value);
// After "is not a number": "; hexadecimal is not read, write it in decimal" for text such as
// "0x10" or "-0X1p3", which strtod would have taken; otherwise nothing. A person who wrote 0x10
// meant a number, and "expected a number, got '0x10'" alone leaves them guessing why.
std::string hexadecimal_hint(const std::string& text);
// What is wrong with text that is not finite or underflows, for a message after the text:
// "is not finite", "is below the smallest number a double holds, so it would read as 0".
std::string number_text_problem(NumberText kind);
// The first number in JSON text (a --params or --airframe file) that reads as 0 only because a
// double cannot hold it (1e-400): nlohmann's parser takes it as 0 without a word. Empty when
// there is none, or the text is no JSON (the parse that follows says so).
std::string json_number_below_a_double(const std::string& json_text);
// What a reader of JSON says of such a number ("the number 1e-400 is below ..."), or nothing.
std::string json_number_problem(const std::string& json_text);

}  // namespace quadgen::output
