//! Subnormal floats flushed to zero on a software adapter's threads.
//!
//! Lavapipe runs the kernels on threads it starts as its device opens, and a
//! thread starts with the floating-point controls of the thread that starts
//! it. Left as a process has them, every operation on a subnormal float (a
//! quaternion's part of 1e-20 squared, a push a path's elimination shrank to
//! nothing) takes the CPU's slow path, a hundred cycles or more: a joint
//! grid's direct solve ran 2.8 times slower for it. GPUs flush such values
//! to zero, and WGSL allows it; so `Gpu::new` opens a software adapter's
//! device with flushing on (x86's FTZ and DAZ), and gives the calling thread
//! back its own controls once the device is open.

/// The calling thread's floating-point controls, with subnormals flushed to
/// zero until dropped, when they are restored.
pub(super) struct FlushToZero {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    saved: u32,
}

/// MXCSR's flush-to-zero (results) and denormals-are-zero (inputs) bits.
#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
const FTZ_DAZ: u32 = 0x8040;

impl FlushToZero {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    pub(super) fn begin() -> FlushToZero {
        let saved = read_mxcsr();
        write_mxcsr(saved | FTZ_DAZ);
        FlushToZero { saved }
    }

    /// Elsewhere nothing changes: lavapipe's kernels there run as they would.
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
    pub(super) fn begin() -> FlushToZero {
        FlushToZero {}
    }
}

impl Drop for FlushToZero {
    fn drop(&mut self) {
        #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
        write_mxcsr(self.saved);
    }
}

#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
fn read_mxcsr() -> u32 {
    let mut csr = 0u32;
    // SAFETY: stores the 32-bit control register into a local.
    unsafe { std::arch::asm!("stmxcsr [{}]", in(reg) &mut csr, options(nostack, preserves_flags)) };
    csr
}

#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
fn write_mxcsr(csr: u32) {
    // SAFETY: loads a value read from the register with two of its mode bits
    // changed (or the saved value back); no exception is unmasked. Rust code
    // run meanwhile (wgpu opening the device) sees subnormals flushed, which
    // only changes results smaller than f32::MIN_POSITIVE.
    unsafe { std::arch::asm!("ldmxcsr [{}]", in(reg) &csr, options(nostack, preserves_flags, readonly)) };
}
