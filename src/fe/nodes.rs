//! The node map: an FE node number → its DOF index per direction (x, y, z), and its coordinates
//! when known. The one place where a scene's `node = …, axis = …` becomes a DOF (and where a
//! contact normal finds the DOFs it acts on).
use std::collections::BTreeMap;

/// One node's DOFs (in the model's numbering; `None` for a direction fixed or absent) and position.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeDofs {
    pub dofs: [Option<usize>; 3],
    pub position: Option<[f64; 3]>,
}

/// Node number → [`NodeDofs`]; `source` names where the numbering comes from in messages
/// (`blade.dof`, "the blade generator").
#[derive(Clone, Debug, PartialEq)]
pub struct NodeMap {
    pub source: String,
    /// Why a node or direction can be missing, and what to do: ends the refusal's message.
    pub missing: String,
    nodes: BTreeMap<u64, NodeDofs>,
}

/// A node or direction that has no DOF.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NodeError {
    #[error("node {node} direction {axis} is not in {map}: {remedy}")]
    Absent { node: u64, axis: &'static str, map: String, remedy: String },
    #[error("axis \"{0}\", expected \"x\", \"y\" or \"z\"")]
    Axis(String),
}

/// The direction index of `"x"`, `"y"`, `"z"`.
pub fn axis_index(axis: &str) -> Result<usize, NodeError> {
    match axis {
        "x" => Ok(0),
        "y" => Ok(1),
        "z" => Ok(2),
        other => Err(NodeError::Axis(other.to_string())),
    }
}

const AXES: [&str; 3] = ["x", "y", "z"];

impl NodeMap {
    pub fn new(source: impl Into<String>, missing: impl Into<String>) -> Self {
        NodeMap { source: source.into(), missing: missing.into(), nodes: BTreeMap::new() }
    }

    /// Records DOF `dof` as direction `axis` (0, 1, 2) of `node`; returns the DOF it had, if any.
    pub fn insert(&mut self, node: u64, axis: usize, dof: usize) -> Option<usize> {
        let entry = self.nodes.entry(node).or_insert(NodeDofs { dofs: [None; 3], position: None });
        entry.dofs[axis].replace(dof)
    }

    pub fn set_position(&mut self, node: u64, position: [f64; 3]) {
        self.nodes.entry(node).or_insert(NodeDofs { dofs: [None; 3], position: None }).position = Some(position);
    }

    pub fn get(&self, node: u64) -> Option<&NodeDofs> {
        self.nodes.get(&node)
    }

    /// The DOF of direction `axis` (0, 1, 2) of `node`, or the refusal naming node, map and remedy.
    pub fn dof(&self, node: u64, axis: usize) -> Result<usize, NodeError> {
        self.get(node).and_then(|n| n.dofs[axis]).ok_or_else(|| NodeError::Absent {
            node,
            axis: AXES[axis],
            map: self.source.clone(),
            remedy: self.missing.clone(),
        })
    }

    /// Every node with its DOFs, by node number.
    pub fn iter(&self) -> impl Iterator<Item = (u64, &NodeDofs)> {
        self.nodes.iter().map(|(n, d)| (*n, d))
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }
}
