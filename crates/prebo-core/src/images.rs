//! Basis functions with their images under the symmetry operations, for any function type.
//!
//! A symmetrised element is `Σ_P c_P <phi_I| O |P phi_J>`; the images `P phi_J` are
//! computed once per function and operation (`Transform::transformed`).
use crate::ecg::{Element, Mat, Real};
use crate::error::Result;

/// A function type that knows its image `phi(T r)` under a linear map `T`.
pub trait Transform<const D: usize, Ctx>: Sized {
    fn transformed(&self, t: &Mat<D>, ctx: &Ctx, index: usize) -> Result<Self>;
}

pub struct Images<F> {
    pub functions: Vec<F>,
    /// `images[j][p]` = function `j` under operation `p`
    pub images: Vec<Vec<F>>,
    pub coef: Vec<f64>,
}

impl<F> Images<F> {
    pub fn new<const D: usize, Ctx>(functions: Vec<F>, sym: &[(Mat<D>, f64)], ctx: &Ctx) -> Result<Self>
    where
        F: Transform<D, Ctx>,
    {
        let images = functions
            .iter()
            .enumerate()
            .map(|(j, f)| sym.iter().map(|(t, _)| f.transformed(t, ctx, j)).collect())
            .collect::<Result<Vec<Vec<_>>>>()?;
        Ok(Self { functions, images, coef: sym.iter().map(|(_, c)| *c).collect() })
    }

    /// The same functions and images with `cast` applied (e.g. to dual numbers).
    pub fn map<G>(&self, cast: impl Fn(&F) -> G) -> Images<G> {
        Images {
            functions: self.functions.iter().map(&cast).collect(),
            images: self.images.iter().map(|im| im.iter().map(&cast).collect()).collect(),
            coef: self.coef.clone(),
        }
    }

    pub fn len(&self) -> usize {
        self.functions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.functions.is_empty()
    }

    /// `Σ_P c_P element(bra, P phi_j)`.
    pub fn element<B, T: Real>(&self, bra: &B, j: usize, element: impl Fn(&B, &F) -> Element<T>) -> Element<T> {
        let mut e = Element::zero();
        for (ket, c) in self.images[j].iter().zip(&self.coef) {
            e += (*c, element(bra, ket));
        }
        e
    }
}
