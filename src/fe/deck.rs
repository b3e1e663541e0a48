//! The blade generator's mesh as a CalculiX deck, so that CalculiX (an independent FE code) can
//! assemble the same blade: nodes numbered index + 1 (the blade's node map), `C3D8` for
//! [`ElementKind::Hex8`] and `C3D8I` (incompatible modes) for [`ElementKind::Hex8Incompatible`],
//! the material, the root clamped by `*BOUNDARY` (node set `ROOT`), the mid-thickness tip nodes
//! LE to TE as node set `TIP`, and a `*FREQUENCY, SOLVER=MATRIXSTORAGE` step
//! that writes `job.sti`, `job.mas` and `job.dof` (read back by [`super::read_calculix`]). Numbers
//! have 13 significant digits: CalculiX reads at most 20 characters per field.
use super::blade::Blade;
use super::hex8::ElementKind;
use std::fmt::Write as _;

impl Blade {
    /// The deck (`.inp` text) of this blade's mesh. The root (z = 0) nodes are clamped.
    pub fn calculix_deck(&self) -> String {
        let p = &self.params;
        let m = p.mesh;
        let mut s = String::new();
        let _ = writeln!(s, "** periodic-contact blade generator: {} x {} x {} hexahedra (span, chord, thickness), SI units", m.span, m.chord, m.thickness);
        let _ = writeln!(s, "** run: ccx JOBNAME   (writes JOBNAME.sti, JOBNAME.mas, JOBNAME.dof)");
        s.push_str("*NODE, NSET=NALL\n");
        for (i, [x, y, z]) in self.nodes.iter().enumerate() {
            let _ = writeln!(s, "{}, {x:.12e}, {y:.12e}, {z:.12e}", i + 1);
        }
        let kind = match p.element {
            ElementKind::Hex8 => "C3D8",
            ElementKind::Hex8Incompatible => "C3D8I",
        };
        let _ = writeln!(s, "*ELEMENT, TYPE={kind}, ELSET=EALL");
        for (e, conn) in self.elements.iter().enumerate() {
            let nodes: Vec<String> = conn.iter().map(|a| (a + 1).to_string()).collect();
            let _ = writeln!(s, "{}, {}", e + 1, nodes.join(", "));
        }
        let root: Vec<usize> = (0..self.nodes.len()).filter(|&i| self.nodes[i][2] == 0.0).collect();
        node_set(&mut s, "ROOT", &root);
        // The contact candidates (`nodes = "tip"`), so that a CalculiX scene can name them.
        node_set(&mut s, "TIP", &self.tip_nodes());
        let mat = &p.material;
        let _ = writeln!(s, "*MATERIAL, NAME=BLADE\n*ELASTIC\n{:.12e}, {:.12e}\n*DENSITY\n{:.12e}", mat.young, mat.poisson, mat.density);
        s.push_str("*SOLID SECTION, ELSET=EALL, MATERIAL=BLADE\n*BOUNDARY\nROOT, 1, 3\n*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n");
        s
    }
}

/// `*NSET` of the node indices `nodes` (numbered index + 1), 16 a line.
fn node_set(s: &mut String, name: &str, nodes: &[usize]) {
    let _ = writeln!(s, "*NSET, NSET={name}");
    for chunk in nodes.chunks(16) {
        let line: Vec<String> = chunk.iter().map(|i| (i + 1).to_string()).collect();
        let _ = writeln!(s, "{},", line.join(", "));
    }
}
