//! The size checks a script passes before rhai's bytecode compiler sees it.
//!
//! rhai's parser is fast, but its `grain` compiler deduplicates constants and names by a
//! linear scan, so its time grows with the square of their number (2 000 one-line helper
//! functions 0.4 s, 4 000 1.8 s, 20 000 over a minute; 8 000 numeric literals in one function
//! 4.3 s). The byte limit is checked on the text, so an enormous file is never parsed; the
//! others are counted on the parsed AST ([`rhai::AST::walk`]), function bodies included. Each
//! refusal names the limit and its `[scripts]` key.

use rhai::{ASTNode, Expr, AST};

use crate::limits::ScriptLimits;

/// The script's text is within [`ScriptLimits::max_bytes`].
pub(crate) fn check_bytes(source: &str, limits: &ScriptLimits) -> Result<(), String> {
    if source.len() > limits.max_bytes {
        return Err(format!(
            "it is {} bytes; the limit is {} bytes (`[scripts] max_bytes`)",
            source.len(),
            limits.max_bytes
        ));
    }
    Ok(())
}

/// The parsed script is within the limits on functions, AST nodes and constants.
pub(crate) fn check_ast(ast: &AST, limits: &ScriptLimits) -> Result<(), String> {
    let functions = ast.iter_functions().count();
    if functions > limits.max_functions {
        return Err(format!(
            "it defines {functions} functions; the limit is {} (`[scripts] max_functions`)",
            limits.max_functions
        ));
    }
    let (mut nodes, mut constants) = (0usize, 0usize);
    ast.walk(&mut |path: &[ASTNode]| {
        nodes += 1;
        // A literal constant: each one is a search of the compiler's pool.
        if let Some(ASTNode::Expr(
            Expr::DynamicConstant(..)
            | Expr::BoolConstant(..)
            | Expr::IntegerConstant(..)
            | Expr::FloatConstant(..)
            | Expr::CharConstant(..)
            | Expr::StringConstant(..),
        )) = path.last()
        {
            constants += 1;
        }
        nodes <= limits.max_nodes && constants <= limits.max_constants
    });
    if nodes > limits.max_nodes {
        return Err(format!(
            "it has more than {} statements and expressions (`[scripts] max_nodes`)",
            limits.max_nodes
        ));
    }
    if constants > limits.max_constants {
        return Err(format!(
            "it writes more than {} constants (`[scripts] max_constants`)",
            limits.max_constants
        ));
    }
    Ok(())
}
