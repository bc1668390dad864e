//! The expression convention of calibrated-law JSON (`grainlaw-expr-1`): the formulas of the
//! law registry ([`crate::law::REGISTRY`]) are written in it, and this module parses and
//! evaluates them, so that a formula written to JSON is checked against the fitted function.
//!
//! Grammar (ASCII, whitespace ignored):
//!
//! ```text
//! expr    := term (('+' | '-') term)*
//! term    := unary (('*' | '/') unary)*
//! unary   := '-' unary | power
//! power   := primary ('^' unary)?          (right associative: a^b^c = a^(b^c))
//! primary := number | name | name '(' expr ')' | '(' expr ')'
//! number  := digits ['.' digits] [('e' | 'E') ['+' | '-'] digits]
//! name    := [A-Za-z_][A-Za-z0-9_]*
//! ```
//!
//! Functions: `exp`, `ln` (natural logarithm), `sqrt`, `sin`, `cos`, `tan` (radians). `-a^b` is
//! `-(a^b)`. Every other name is a variable: the law's input, its parameters and constants (the
//! keys of `parameters` and `constants` in the JSON), an earlier output, or a name defined in
//! `where`. Arithmetic is IEEE double precision.

use std::collections::BTreeMap;

use crate::error::{IdentifyError, Result};

/// The functions of the convention.
pub const FUNCTIONS: [&str; 6] = ["exp", "ln", "sqrt", "sin", "cos", "tan"];

/// A parsed expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A number.
    Number(f64),
    /// A variable.
    Variable(String),
    /// `-e`.
    Neg(Box<Expr>),
    /// `a op b` with `op` one of `+ - * / ^`.
    Binary(char, Box<Expr>, Box<Expr>),
    /// `f(e)`.
    Call(String, Box<Expr>),
}

fn format_error(text: &str, message: String) -> IdentifyError {
    IdentifyError::LawFormat {
        message: format!("formula '{text}': {message}"),
    }
}

struct Parser<'a> {
    text: &'a str,
    chars: Vec<char>,
    at: usize,
}

impl Parser<'_> {
    fn skip(&mut self) {
        while self.at < self.chars.len() && self.chars[self.at].is_whitespace() {
            self.at += 1;
        }
    }

    fn peek(&mut self) -> Option<char> {
        self.skip();
        self.chars.get(self.at).copied()
    }

    fn error(&self, what: &str) -> IdentifyError {
        format_error(self.text, format!("{what} at character {}", self.at + 1))
    }

    fn expr(&mut self) -> Result<Expr> {
        let mut left = self.term()?;
        while let Some(op @ ('+' | '-')) = self.peek() {
            self.at += 1;
            left = Expr::Binary(op, Box::new(left), Box::new(self.term()?));
        }
        Ok(left)
    }

    fn term(&mut self) -> Result<Expr> {
        let mut left = self.unary()?;
        while let Some(op @ ('*' | '/')) = self.peek() {
            self.at += 1;
            left = Expr::Binary(op, Box::new(left), Box::new(self.unary()?));
        }
        Ok(left)
    }

    fn unary(&mut self) -> Result<Expr> {
        if self.peek() == Some('-') {
            self.at += 1;
            return Ok(Expr::Neg(Box::new(self.unary()?)));
        }
        self.power()
    }

    fn power(&mut self) -> Result<Expr> {
        let base = self.primary()?;
        if self.peek() == Some('^') {
            self.at += 1;
            return Ok(Expr::Binary('^', Box::new(base), Box::new(self.unary()?)));
        }
        Ok(base)
    }

    fn primary(&mut self) -> Result<Expr> {
        match self.peek() {
            Some('(') => {
                self.at += 1;
                let e = self.expr()?;
                if self.peek() != Some(')') {
                    return Err(self.error("expected ')'"));
                }
                self.at += 1;
                Ok(e)
            }
            Some(c) if c.is_ascii_digit() || c == '.' => self.number(),
            Some(c) if c.is_ascii_alphabetic() || c == '_' => {
                let start = self.at;
                while self.at < self.chars.len()
                    && (self.chars[self.at].is_ascii_alphanumeric() || self.chars[self.at] == '_')
                {
                    self.at += 1;
                }
                let name: String = self.chars[start..self.at].iter().collect();
                if self.peek() == Some('(') {
                    if !FUNCTIONS.contains(&name.as_str()) {
                        return Err(self.error(&format!("unknown function '{name}'")));
                    }
                    self.at += 1;
                    let arg = self.expr()?;
                    if self.peek() != Some(')') {
                        return Err(self.error("expected ')'"));
                    }
                    self.at += 1;
                    return Ok(Expr::Call(name, Box::new(arg)));
                }
                Ok(Expr::Variable(name))
            }
            _ => Err(self.error("expected a number, a name or '('")),
        }
    }

    fn number(&mut self) -> Result<Expr> {
        let start = self.at;
        let digits = |p: &mut Self| {
            while p.at < p.chars.len() && p.chars[p.at].is_ascii_digit() {
                p.at += 1;
            }
        };
        digits(self);
        if self.chars.get(self.at) == Some(&'.') {
            self.at += 1;
            digits(self);
        }
        if matches!(self.chars.get(self.at), Some('e' | 'E')) {
            self.at += 1;
            if matches!(self.chars.get(self.at), Some('+' | '-')) {
                self.at += 1;
            }
            digits(self);
        }
        let s: String = self.chars[start..self.at].iter().collect();
        s.parse()
            .map(Expr::Number)
            .map_err(|_| self.error(&format!("bad number '{s}'")))
    }
}

impl Expr {
    /// Parses `text` (grammar in the module documentation). Errors:
    /// [`IdentifyError::LawFormat`] naming the formula and the character.
    pub fn parse(text: &str) -> Result<Expr> {
        let mut p = Parser {
            text,
            chars: text.chars().collect(),
            at: 0,
        };
        let e = p.expr()?;
        if p.peek().is_some() {
            return Err(p.error("unexpected character"));
        }
        Ok(e)
    }

    /// Evaluates with the variables in `vars`. Errors: [`IdentifyError::LawFormat`] for a
    /// variable not in `vars`.
    pub fn eval(&self, vars: &BTreeMap<String, f64>) -> Result<f64> {
        Ok(match self {
            Expr::Number(v) => *v,
            Expr::Variable(n) => *vars.get(n).ok_or_else(|| IdentifyError::LawFormat {
                message: format!("formula variable '{n}' has no value"),
            })?,
            Expr::Neg(e) => -e.eval(vars)?,
            Expr::Binary(op, a, b) => {
                let (a, b) = (a.eval(vars)?, b.eval(vars)?);
                match op {
                    '+' => a + b,
                    '-' => a - b,
                    '*' => a * b,
                    '/' => a / b,
                    _ => a.powf(b),
                }
            }
            Expr::Call(f, e) => {
                let v = e.eval(vars)?;
                match f.as_str() {
                    "exp" => v.exp(),
                    "ln" => v.ln(),
                    "sqrt" => v.sqrt(),
                    "sin" => v.sin(),
                    "cos" => v.cos(),
                    _ => v.tan(),
                }
            }
        })
    }

    /// The expression as C source (C99 `<math.h>`), every operation parenthesised so that C
    /// evaluates the same tree in the same order: `a^b` → `pow(a, b)`, `ln` → `log`, the other
    /// functions by their own name. Each variable is replaced by `subst(name)`: a C expression
    /// (a literal, a variable of the calling code), or `None` for a variable with no value
    /// ([`IdentifyError::LawFormat`]). Numbers are written in Rust's shortest round-trip form
    /// (`{:?}`), which a C compiler reads back to the same double (IEEE 754, round to nearest).
    pub fn to_c(&self, subst: &dyn Fn(&str) -> Option<String>) -> Result<String> {
        Ok(match self {
            Expr::Number(v) => c_literal(*v),
            Expr::Variable(n) => subst(n).ok_or_else(|| IdentifyError::LawFormat {
                message: format!("formula variable '{n}' has no value"),
            })?,
            Expr::Neg(e) => format!("(-{})", e.to_c(subst)?),
            Expr::Binary('^', a, b) => format!("pow({}, {})", a.to_c(subst)?, b.to_c(subst)?),
            Expr::Binary(op, a, b) => format!("({} {op} {})", a.to_c(subst)?, b.to_c(subst)?),
            Expr::Call(f, e) => {
                let name = if f == "ln" { "log" } else { f.as_str() };
                format!("{name}({})", e.to_c(subst)?)
            }
        })
    }

    /// The variable names the expression uses (sorted, each once).
    pub fn variables(&self) -> Vec<String> {
        let mut out = Vec::new();
        self.collect(&mut out);
        out.sort();
        out.dedup();
        out
    }

    fn collect(&self, out: &mut Vec<String>) {
        match self {
            Expr::Number(_) => {}
            Expr::Variable(n) => out.push(n.clone()),
            Expr::Neg(e) | Expr::Call(_, e) => e.collect(out),
            Expr::Binary(_, a, b) => {
                a.collect(out);
                b.collect(out);
            }
        }
    }
}

/// A double as a C literal that reads back to the same value: Rust's shortest round-trip
/// digits (`{:?}`), with a `.0` kept so that C reads a double, never an integer; negative values
/// parenthesised; non-finite values as `(1.0/0.0)`, `(-1.0/0.0)`, `(0.0/0.0)`.
pub fn c_literal(v: f64) -> String {
    if v.is_nan() {
        "(0.0/0.0)".into()
    } else if v.is_infinite() {
        if v > 0.0 {
            "(1.0/0.0)".into()
        } else {
            "(-1.0/0.0)".into()
        }
    } else if v < 0.0 || (v == 0.0 && v.is_sign_negative()) {
        format!("(-{:?})", -v)
    } else {
        format!("{v:?}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eval(text: &str, vars: &[(&str, f64)]) -> f64 {
        let v = vars.iter().map(|(k, v)| (k.to_string(), *v)).collect();
        Expr::parse(text).unwrap().eval(&v).unwrap()
    }

    #[test]
    fn precedence_and_functions() {
        assert_eq!(eval("1 + 2*3", &[]), 7.0);
        assert_eq!(eval("(1 + 2)*3", &[]), 9.0);
        assert_eq!(eval("2^3^2", &[]), 512.0);
        assert_eq!(eval("-2^2", &[]), -4.0);
        assert_eq!(eval("8/2/2", &[]), 2.0);
        assert_eq!(eval("1.5e2 - x", &[("x", 50.0)]), 100.0);
        assert!((eval("exp(ln(3)) + sqrt(4) + tan(0) + sin(0) + cos(0)", &[]) - 6.0).abs() < 1e-15);
        assert_eq!(
            Expr::parse("a*exp(-b/c) + a").unwrap().variables(),
            ["a", "b", "c"]
        );
    }

    #[test]
    fn bad_formulas_are_errors() {
        for bad in ["1 +", "f(2)", "(1", "2 3", "", "1..2"] {
            assert!(Expr::parse(bad).is_err(), "{bad}");
        }
        assert!(Expr::parse("x").unwrap().eval(&BTreeMap::new()).is_err());
    }
    #[test]
    fn c_source_keeps_the_tree_and_the_digits() {
        let e = Expr::parse("mu_s + (mu_2 - mu_s)*I/(I + I_0)").unwrap();
        let c = e
            .to_c(&|n| match n {
                "I" => Some("In".into()),
                "mu_s" => Some(c_literal(0.31999475797599297)),
                "mu_2" => Some(c_literal(0.6)),
                "I_0" => Some(c_literal(1e-7)),
                _ => None,
            })
            .unwrap();
        assert_eq!(
            c,
            "(0.31999475797599297 + (((0.6 - 0.31999475797599297) * In) / (In + 1e-7)))"
        );
        let p = Expr::parse("-a^2 + ln(b)").unwrap();
        assert_eq!(
            p.to_c(&|n| Some(n.to_string())).unwrap(),
            "((-pow(a, 2.0)) + log(b))"
        );
        assert!(p.to_c(&|_| None).is_err());
        assert_eq!(c_literal(-2.5), "(-2.5)");
        assert_eq!(c_literal(3.0), "3.0");
        for v in [0.1, 1.0 / 3.0, 6.02214076e23, 5e-324] {
            assert_eq!(c_literal(v).parse::<f64>().unwrap(), v);
        }
    }
}
