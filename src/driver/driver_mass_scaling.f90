!> *FIXED MASS SCALING: element masses scaled once at the start of the step that defines it, for
!> quasi-static steps whose natural time is irrelevant (gravity settling, slow sliding).
!>
!> Semantics (Abaqus/Explicit's, docs/keywords.md): FACTOR scales the masses of the set's elements;
!> with DT, the masses (already times FACTOR) are scaled again so that the element stable
!> increment reaches DT — BELOW MIN: only the elements below DT, each to exactly DT; UNIFORM: all
!> by one factor so that the smallest reaches DT. The increments are measured on the geometry at
!> the step start, with the step's linear bulk viscosity, like the solver's own estimate. A
!> step without a definition keeps the scaled masses of the step before (Abaqus); a step with
!> definitions starts again from the physical masses (FACTOR=1 alone restores them).
!> Where we differ from Abaqus: factors are never below 1 (UNIFORM with DT above the smallest
!> increment does not lighten the model); several definitions naming one element: the last wins.
!>
!> What sees the scaled mass: nodal masses (inertia), the stable increment, the kinetic energy
!> ALLKE, the bulk-viscosity and hourglass forces (they scale with ρ c). What does not: gravity
!> (the weight stays physical, so the quasi-static state does not depend on the factor), the
!> density passed to the VUMAT and the internal energy (specific energy × physical mass).
!> Energy balance across a change of the masses: the velocities are kept, so ALLKE jumps by
!> ½ Σ Δm v²; that jump is booked in ALLWK (as work done on the model by the mass change), so
!> ETOTAL stays continuous.
module driver_mass_scaling
  use, intrinsic :: iso_fortran_env, only: output_unit
  use base_kinds, only: dp
  use model, only: model_t
  use model_mesh, only: element_cpe4r, element_cax4r
  use model_steps, only: mass_scaling_uniform
  use parallel_assembly, only: assemble_element_vectors, global_min, global_max
  use driver_solver, only: solver_t
  use fem_cpe4r, only: cpe4r_geometry, cpe4r_char_length
  use fem_cax4r, only: cax4r_geometry, cax4r_char_length
  use driver_setup, only: shared_node_mass
  use fem_c3d8r, only: c3d8r_geometry, c3d8r_char_length
  use fem_stable_dt, only: element_stable_dt
  use fem_mass, only: lumped_mass
  implicit none
  private

  public :: apply_step_mass_scaling

contains

  !> At the start of step istep (before its first increment): if the step defines mass
  !> scaling, recompute every element's factor from the physical masses, re-assemble the nodal
  !> masses, book the kinetic-energy jump and return the new stable increment in dt_stable
  !> (unchanged when the step defines nothing). Prints one line on rank 0.
  subroutine apply_step_mass_scaling(m, istep, solver, dt_stable)
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    type(solver_t), intent(inout) :: solver
    real(dp), intent(inout) :: dt_stable
    real(dp), allocatable :: dt_el(:), mass_e(:, :, :), mass_b(:, :), mass2(:, :)
    logical, allocatable :: in_set(:)
    real(dp) :: f, dt_min_set, fmin, fmax, dke, old_mass
    integer :: ib, e, k, nb, i, le

    associate (s => m%steps(istep))
      if (.not. s%mass_scaling_defined) return
      ! Element stable increments with the physical masses on the current geometry.
      allocate(dt_el(solver%part%n_local_elems))
      call element_increments(m, solver, s%bulk_linear, dt_el)
      do ib = 1, solver%n_blocks
         associate (blk => solver%blocks(ib))
           if (.not. allocated(blk%mass_scale)) allocate(blk%mass_scale(blk%count))
           blk%mass_scale = 1
         end associate
      end do
      allocate(in_set(m%mesh%n_elems))
      do k = 1, size(s%mass_scaling)
         associate (ms => s%mass_scaling(k))
           in_set = ms%elset == 0
           if (ms%elset > 0) in_set(m%elsets(ms%elset)%members) = .true.
           ! UNIFORM: the smallest increment of the set (all ranks), after FACTOR.
           dt_min_set = huge(1.0_dp)
           do le = 1, solver%part%n_local_elems
              if (in_set(solver%part%elem_global(le))) dt_min_set = min(dt_min_set, dt_el(le))
           end do
           call global_min(solver%part, dt_min_set)
           dt_min_set = dt_min_set * sqrt(ms%factor)
           do ib = 1, solver%n_blocks
              associate (blk => solver%blocks(ib))
                do e = 1, blk%count
                   le = blk%first + e - 1
                   if (.not. in_set(solver%part%elem_global(le))) cycle
                   f = ms%factor
                   if (ms%dt > 0) then
                      if (ms%kind == mass_scaling_uniform) then
                         f = f * max(1.0_dp, (ms%dt / dt_min_set)**2)
                      else
                         f = f * max(1.0_dp, (ms%dt / (dt_el(le) * sqrt(f)))**2)
                      end if
                   end if
                   blk%mass_scale(e) = f
                end do
              end associate
           end do
         end associate
      end do

      ! Nodal masses from the scaled element masses, as the set-up assembles the physical ones.
      allocate(mass_e(solver%part%n_local_elems, 1, solver%nen), mass2(1, solver%n_nodes))
      fmin = huge(1.0_dp)
      fmax = 0
      dt_stable = huge(1.0_dp)
      do ib = 1, solver%n_blocks
         associate (blk => solver%blocks(ib))
           nb = blk%count
           blk%mass_scaled = maxval(abs(blk%mass_scale - 1)) > 0
           allocate(mass_b(nb, solver%nen))
           call lumped_mass(nb, solver%nen, blk%mass * blk%mass_scale / blk%volume_ref, blk%volume_ref, mass_b)
           if (allocated(blk%mass_share)) call shared_node_mass(nb, solver%nen, blk%mass * blk%mass_scale, &
                blk%mass_share, mass_b)
           mass_e(blk%first:blk%first + nb - 1, 1, :) = mass_b
           deallocate(mass_b)
           fmin = min(fmin, minval(blk%mass_scale))
           fmax = max(fmax, maxval(blk%mass_scale))
           do e = 1, nb
              dt_stable = min(dt_stable, dt_el(blk%first + e - 1) * sqrt(blk%mass_scale(e)))
           end do
         end associate
      end do
      call assemble_element_vectors(solver%part, 1, mass_e, mass2)
      dke = 0
      do i = 1, solver%n_nodes
         old_mass = solver%mass(i)
         if (old_mass <= 0) cycle            ! a reference node: no elements, no mass
         if (solver%part%node_owned(i)) dke = dke + 0.5_dp * (mass2(1, i) - old_mass) * sum(solver%v(:, i)**2)
         solver%mass(i) = mass2(1, i)
      end do
      solver%e_external = solver%e_external + dke
      call global_min(solver%part, dt_stable)
      call global_min(solver%part, fmin)
      call global_max(solver%part, fmax)
      if (solver%part%rank == 0) then
         write (output_unit, '(a,i0,a,es10.3,a,es10.3,a,es10.3)') '  mass scaling  step ', istep, &
              ': element factors ', fmin, ' .. ', fmax, ', stable increment ', dt_stable
         flush (output_unit)
      end if
    end associate
  end subroutine apply_step_mass_scaling

  !> Stable increment of every local element with its physical mass on the current geometry
  !> (x0 + u) and the linear bulk-viscosity damping b1: the estimate the solver itself uses.
  subroutine element_increments(m, solver, b1, dt_el)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    real(dp), intent(in) :: b1
    real(dp), intent(out) :: dt_el(:)
    real(dp), allocatable :: xe(:, :, :), lc(:), c(:), xi(:), dte(:), vol(:), bmat(:, :, :)
    real(dp), allocatable :: hoop(:, :), share(:, :)
    integer :: ib, nb, e, a, i, node

    do ib = 1, solver%n_blocks
       associate (blk => solver%blocks(ib))
         nb = blk%count
         allocate(xe(nb, solver%ndim, solver%nen), lc(nb), c(nb), xi(nb), dte(nb), vol(nb))
         allocate(bmat(nb, solver%ndim, solver%nen))
         do a = 1, solver%nen
            do i = 1, solver%ndim
               do e = 1, nb
                  node = solver%part%conn(a, blk%first + e - 1)
                  xe(e, i, a) = solver%x0(i, node) + solver%u(i, node)
               end do
            end do
         end do
         if (m%mesh%element_type == element_cpe4r) then
            call cpe4r_geometry(nb, xe, m%sections(blk%section)%thickness, vol, bmat)
            call cpe4r_char_length(nb, xe, lc)
         else if (m%mesh%element_type == element_cax4r) then
            allocate(hoop(nb, 4), share(nb, 4))
            call cax4r_geometry(nb, xe, vol, bmat, hoop, share)
            call cax4r_char_length(nb, xe, lc)
            deallocate(hoop, share)
         else
            call c3d8r_geometry(nb, xe, vol, bmat)
            call c3d8r_char_length(nb, xe, vol, lc)
         end if
         c = sqrt(blk%wave_modulus / (blk%mass / abs(vol)))
         xi = b1
         call element_stable_dt(nb, lc, c, xi, dte)
         dt_el(blk%first:blk%first + nb - 1) = dte
         deallocate(xe, lc, c, xi, dte, vol, bmat)
       end associate
    end do
  end subroutine element_increments
end module driver_mass_scaling
