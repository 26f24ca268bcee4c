//! Records (placeholder until the reader lands).
/// A record.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Record {
    /// Source.
    pub source: String,
    /// t.
    pub t: Vec<f64>,
    /// x.
    pub x: Vec<f64>,
    /// phi.
    pub phi: Option<Vec<f64>>,
    /// f.
    pub f_stf: Option<Vec<f64>>,
    /// w.
    pub omega: Option<Vec<f64>>,
    /// u.
    pub u: Option<Vec<f64>>,
}
impl Record {
    /// Write CSV (placeholder).
    pub fn write_csv(&self, path: &std::path::Path) -> std::io::Result<()> {
        use std::io::Write;
        let mut s = String::from("t,x\n");
        for (t, x) in self.t.iter().zip(&self.x) {
            s.push_str(&format!("{t},{x}\n"));
        }
        std::fs::File::create(path)?.write_all(s.as_bytes())
    }
}
