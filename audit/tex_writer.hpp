// LaTeX of the model's expressions for the derivation report: identical for identical
// expressions whatever order GiNaC keeps their operands in (that order depends on symbol
// serial numbers, i.e. on the process, and a reviewer diffs reports), with the operands of
// sums and products in the order the generated code emits them (derive/term_order.hpp).
#pragma once
#include <map>
#include <string>

#include <ginac/ginac.h>

#include "derive/symbolic_model.hpp"
#include "derive/term_order.hpp"

namespace quadgen {

class TexWriter {
 public:
  explicit TexWriter(const SymbolicModel& m) : places_(m) {}
  std::string tex(const GiNaC::ex& e);  // memoised: shared subexpressions are printed once
  std::string matrix(const GiNaC::matrix& m);

 private:
  std::string uncached(const GiNaC::ex& e);
  std::string operand(const GiNaC::ex& e, bool as_base);
  std::string sum(const GiNaC::ex& e);
  std::string product(const GiNaC::ex& e);
  std::string power(const GiNaC::ex& e);
  std::string function(const GiNaC::ex& e);
  std::string factor_text(const GiNaC::ex& f, bool* sign);
  bool leading_term_negative(const GiNaC::ex& sum);
  // Operands in the shared order: by support, then by their text.
  struct Written {
    term_order::Support support;
    std::string text;
    bool negative = false;
  };
  static void sort(std::vector<Written>& v);
  std::vector<Written> sorted_terms(const GiNaC::ex& sum);

  term_order::SymbolPlaces places_;
  std::map<GiNaC::ex, std::string, GiNaC::ex_is_less> cache_;
};

}  // namespace quadgen
