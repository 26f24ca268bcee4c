fn main() {
    let src = std::env::args().nth(1).unwrap();
    let ast = stf_plugins::sandbox::engine().compile(&src).unwrap();
    for f in ast.iter_fn_def() {
        println!("fn {} {:?}\n{:#?}", f.name, f.params, f.body);
    }
}
