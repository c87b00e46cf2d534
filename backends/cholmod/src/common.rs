//! RAII wrapper of `cholmod_common`: started on creation, finished in `Drop`, kept boxed so its
//! address stays fixed.

use fibercell_solver::SolverError;
use suitesparse_sys as ss;

pub(crate) struct Common(Box<ss::cholmod_common>);

impl Common {
    pub(crate) fn start() -> Result<Self, SolverError> {
        // SAFETY: cholmod_common is plain data; cholmod_l_start initialises every field.
        let mut c: Box<ss::cholmod_common> = Box::new(unsafe { std::mem::zeroed() });
        let ok = unsafe { ss::cholmod_l_start(&mut *c) };
        if ok == 0 {
            return Err(SolverError::Unavailable {
                backend: "cholmod",
                reason: "cholmod_l_start failed".into(),
            });
        }
        c.print = 0;
        Ok(Common(c))
    }

    pub(crate) fn as_mut_ptr(&mut self) -> *mut ss::cholmod_common {
        &mut *self.0
    }
}

impl Drop for Common {
    fn drop(&mut self) {
        // SAFETY: started in `start`; everything allocated with it was freed before.
        unsafe {
            ss::cholmod_l_finish(&mut *self.0);
        }
    }
}
