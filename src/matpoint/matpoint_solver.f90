!> Mixed-control material-point solver: drives a VUMAT along a loading path.
!>
!> Per increment the strain increments of the strain-controlled components are known and
!> those of the stress-controlled components are unknown. They are found by Newton's
!> method on r(dε_u) = σ_new,u(dε) − σ_target,u. Because a VUMAT is a function of the old
!> state and the increment only, the Jacobian comes from ONE block call: point 1 carries
!> the current guess, point 1+j the same old state with dε_u(j) perturbed by h — a forward
!> difference that is an exact use of the VUMAT contract, not an approximation of the
!> state. Newton stops when max|r| <= tolerance × stress scale (default 1e-12). A singular
!> finite-difference Jacobian (e.g. perfect plasticity at the limit) is replaced by the
!> elastic stiffness from the packaging call. When an iteration gains less than a factor 10
!> the answer sits on a kink of the response (a Mohr-Coulomb edge, the elastic-plastic
!> transition), where one-sided differences mislead; Broyden updates then make the Jacobian
!> exact along the steps taken (a handful of iterations instead of dozens). No convergence
!> is reported as an error at the stage's file:line, never as NaN.
!>
!> Sequence: packaging call (moduli for the first guess), then for every increment of
!> every stage: [vusdfld] + vumat on the block, Newton update, accept point 1. The whole
!> path is one Abaqus step: stepTime = totalTime = time at the END of the increment (so
!> the first increment is never mistaken for the packaging call, which has time 0).
module matpoint_solver
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use model_materials, only: material_t
  use matpoint_path, only: matpoint_path_t, matpoint_stage_t, control_strain, control_stress, &
       control_stress_hold, component_label
  use matpoint_block, only: point_block_t
  use material_door, only: checked_packaging_moduli
  use matpoint_dense_solve, only: solve_dense
  implicit none
  private

  public :: matpoint_history_t, run_material_point, elastic_stiffness

  !> Relative size of the finite-difference perturbation (see `increment_newton`).
  real(dp), parameter :: fd_relative_step = 1.0e-7_dp
  !> Pivot threshold (relative) below which a Jacobian counts as singular.
  real(dp), parameter :: singular_tolerance = 1.0e-10_dp
  !> Residual reduction per iteration counted as good progress (keep the FD Jacobian).
  real(dp), parameter :: fast_ratio = 0.1_dp

  !> Everything the run produced: row 1 is the initial state, then one row per increment.
  type :: matpoint_history_t
     integer :: n_rows = 0, ncomp = 0, nstatev = 0, nfieldv = 0
     real(dp), allocatable :: time(:)
     integer, allocatable :: stage(:)            !< 0 for the initial row
     integer, allocatable :: iterations(:)       !< Newton iterations of the increment
     real(dp), allocatable :: strain(:, :)       !< (ncomp, row) log strain, tensor shear
     real(dp), allocatable :: stress(:, :)       !< (ncomp, row) Cauchy, tension positive
     real(dp), allocatable :: state(:, :)        !< (nstatev, row)
     real(dp), allocatable :: field(:, :)        !< (nfieldv, row) fields used in the increment
     real(dp), allocatable :: ener_intern(:), ener_inelas(:)   !< per unit mass
     real(dp) :: two_g = 0.0_dp, bulk = 0.0_dp   !< moduli from the packaging call
  end type matpoint_history_t

  !> The state of the material point between increments.
  type :: point_t
     real(dp), allocatable :: strain(:), stress(:), state(:), field(:)
     real(dp) :: ener_intern = 0.0_dp, ener_inelas = 0.0_dp, time = 0.0_dp
  end type point_t

contains

  !> Run the whole path. On error `err` (or stderr + stop) says where and why.
  subroutine run_material_point(mat, path, history, err)
    type(material_t), intent(in) :: mat
    type(matpoint_path_t), intent(in) :: path
    type(matpoint_history_t), intent(out) :: history
    type(error_t), intent(inout), optional :: err
    type(error_t) :: local

    call run_path(mat, path, history, local)
    if (local%raised) call raise_error('', 0, local%message, err)
  end subroutine run_material_point

  subroutine run_path(mat, path, history, err)
    type(material_t), intent(in) :: mat
    type(matpoint_path_t), intent(in) :: path
    type(matpoint_history_t), intent(inout) :: history
    type(error_t), intent(inout) :: err
    type(point_t) :: pt
    integer :: ncomp, nrows, s, row

    ncomp = path%ncomp()
    call check_inputs(mat, path, err)
    if (err%raised) return

    allocate (pt%strain(ncomp), pt%stress(ncomp), pt%state(mat%nstatev), pt%field(mat%nfieldv))
    pt%strain = 0.0_dp
    pt%stress = path%initial_stress(1:ncomp)
    pt%state = 0.0_dp
    if (allocated(path%initial_state)) pt%state(1:size(path%initial_state)) = path%initial_state
    pt%field = 0.0_dp
    if (allocated(path%initial_field)) pt%field(1:size(path%initial_field)) = path%initial_field

    nrows = 1 + sum(path%stages(1:path%n_stages)%n_increments)
    call allocate_history(history, nrows, ncomp, mat%nstatev, mat%nfieldv)

    call checked_packaging_moduli(mat, ncomp, pt%field, &
         path%stages(1)%duration / path%stages(1)%n_increments, '', history%two_g, history%bulk, err)
    if (err%raised) return

    row = 1
    call record(history, row, pt, 0, 0)
    do s = 1, path%n_stages
       call run_stage(mat, path, s, history, pt, row, err)
       if (err%raised) return
    end do
  end subroutine run_path

  subroutine check_inputs(mat, path, err)
    type(material_t), intent(in) :: mat
    type(matpoint_path_t), intent(in) :: path
    type(error_t), intent(inout) :: err
    integer :: s

    if (.not. allocated(mat%props)) then
       call raise_error('', 0, 'the material has no constants (props)', err)
       return
    end if
    if (path%n_stages < 1) then
       call raise_error('', 0, 'the loading path has no stage', err)
       return
    end if
    if (allocated(path%initial_state)) then
       if (size(path%initial_state) > mat%nstatev) then
          call raise_error('', 0, 'more initial state variables than *DEPVAR declares', err)
          return
       end if
    end if
    if (allocated(path%initial_field)) then
       if (size(path%initial_field) > mat%nfieldv) then
          call raise_error('', 0, 'initial field variable beyond the number of fields', err)
          return
       end if
    end if
    do s = 1, path%n_stages
       if (path%stages(s)%n_increments < 1 .or. .not. (path%stages(s)%duration > 0.0_dp)) then
          call raise_error('', 0, 'a stage needs at least one increment and a positive duration', err)
          call stage_error(path%stages(s), s, 0, err)
          return
       end if
    end do
  end subroutine check_inputs

  subroutine allocate_history(h, nrows, ncomp, nstatev, nfieldv)
    type(matpoint_history_t), intent(inout) :: h
    integer, intent(in) :: nrows, ncomp, nstatev, nfieldv

    h%n_rows = 0
    h%ncomp = ncomp
    h%nstatev = nstatev
    h%nfieldv = nfieldv
    allocate (h%time(nrows), h%stage(nrows), h%iterations(nrows))
    allocate (h%strain(ncomp, nrows), h%stress(ncomp, nrows), h%state(nstatev, nrows))
    allocate (h%field(nfieldv, nrows), h%ener_intern(nrows), h%ener_inelas(nrows))
  end subroutine allocate_history

  subroutine record(h, row, pt, stage, iterations)
    type(matpoint_history_t), intent(inout) :: h
    integer, intent(in) :: row
    type(point_t), intent(in) :: pt
    integer, intent(in) :: stage, iterations

    h%n_rows = row
    h%time(row) = pt%time
    h%stage(row) = stage
    h%iterations(row) = iterations
    h%strain(:, row) = pt%strain
    h%stress(:, row) = pt%stress
    h%state(:, row) = pt%state
    h%field(:, row) = pt%field
    h%ener_intern(row) = pt%ener_intern
    h%ener_inelas(row) = pt%ener_inelas
  end subroutine record

  !> Elastic stiffness for tensor shear strains: σ_ii = λ tr ε + 2G ε_ii, σ_ij = 2G ε_ij.
  pure function elastic_stiffness(ncomp, two_g, bulk) result(c)
    integer, intent(in) :: ncomp
    real(dp), intent(in) :: two_g, bulk
    real(dp) :: c(ncomp, ncomp)
    real(dp) :: lam
    integer :: i

    lam = bulk - two_g / 3.0_dp
    c = 0.0_dp
    c(1:3, 1:3) = lam
    do i = 1, ncomp
       c(i, i) = c(i, i) + two_g
    end do
  end function elastic_stiffness

  !> All increments of stage `s`.
  subroutine run_stage(mat, path, s, history, pt, row, err)
    type(material_t), intent(in) :: mat
    type(matpoint_path_t), intent(in) :: path
    integer, intent(in) :: s
    type(matpoint_history_t), intent(inout) :: history
    type(point_t), intent(inout) :: pt
    integer, intent(inout) :: row
    type(error_t), intent(inout) :: err
    type(matpoint_stage_t) :: stage
    type(point_block_t) :: blk
    integer :: ncomp, nu, i, j, inc, iterations
    integer, allocatable :: iu(:)
    real(dp), allocatable :: sig_start(:), target_end(:), target(:), de(:), c_el(:, :)
    real(dp), allocatable :: de_u_prev(:)
    real(dp) :: dt, frac
    logical :: have_prev

    stage = path%stages(s)
    ncomp = path%ncomp()
    dt = stage%duration / stage%n_increments
    allocate (c_el(ncomp, ncomp), sig_start(ncomp))
    c_el = elastic_stiffness(ncomp, history%two_g, history%bulk)
    sig_start = pt%stress

    ! unknowns: the stress-controlled components
    nu = count(stage%control(1:ncomp) /= control_strain)
    allocate (iu(nu), target_end(nu), target(nu), de_u_prev(nu))
    j = 0
    do i = 1, ncomp
       if (stage%control(i) /= control_strain) then
          j = j + 1
          iu(j) = i
       end if
    end do
    do j = 1, nu
       if (stage%control(iu(j)) == control_stress) then
          target_end(j) = stage%value(iu(j))
       else
          target_end(j) = sig_start(iu(j))
       end if
    end do

    call blk%init(1 + nu, ncomp, mat, path%temperature)
    allocate (de(ncomp))
    have_prev = .false.
    de_u_prev = 0.0_dp
    do inc = 1, stage%n_increments
       frac = real(inc, dp) / real(stage%n_increments, dp)
       do j = 1, nu
          target(j) = sig_start(iu(j)) + (target_end(j) - sig_start(iu(j))) * frac
       end do
       do i = 1, ncomp
          de(i) = 0.0_dp
          if (stage%control(i) == control_strain) de(i) = stage%value(i) / stage%n_increments
       end do
       ! first guess: the previous increment's answer (exact in steady flow), else elastic
       if (have_prev) then
          de(iu) = de_u_prev
       else
          call elastic_guess(ncomp, iu, c_el, pt%stress, target, de)
       end if
       call increment_newton(mat, path, blk, pt, iu, target, c_el, dt, de, iterations, err)
       if (err%raised) then
          call stage_error(stage, s, inc, err)
          return
       end if
       de_u_prev = de(iu)
       have_prev = .true.
       row = row + 1
       call record(history, row, pt, s, iterations)
    end do
  end subroutine run_stage

  !> dε_u from the elastic stiffness: C_uu dε_u = (σ_target − σ_old)_u − C_uk dε_k.
  subroutine elastic_guess(ncomp, iu, c_el, stress, target, de)
    integer, intent(in) :: ncomp
    integer, intent(in) :: iu(:)
    real(dp), intent(in) :: c_el(ncomp, ncomp), stress(ncomp), target(:)
    real(dp), intent(inout) :: de(ncomp)
    real(dp) :: rhs(size(iu)), x(size(iu)), known(ncomp)
    logical :: singular

    if (size(iu) == 0) return
    known = de
    known(iu) = 0.0_dp
    rhs = target - stress(iu) - matmul(c_el(iu, :), known)
    call solve_dense(size(iu), c_el(iu, iu), rhs, x, singular, singular_tolerance)
    de(iu) = 0.0_dp
    if (.not. singular) de(iu) = x
  end subroutine elastic_guess

  !> Newton iterations of one increment; on success `pt` holds the new state.
  subroutine increment_newton(mat, path, blk, pt, iu, target, c_el, dt, de, iterations, err)
    type(material_t), intent(in) :: mat
    type(matpoint_path_t), intent(in) :: path
    type(point_block_t), intent(inout) :: blk
    type(point_t), intent(inout) :: pt
    integer, intent(in) :: iu(:)
    real(dp), intent(in) :: target(:), c_el(:, :), dt
    real(dp), intent(inout) :: de(:)
    integer, intent(out) :: iterations
    type(error_t), intent(inout) :: err
    integer :: nu, ncomp, j, iter
    real(dp) :: scale, h, t_new, res, res_tol
    real(dp) :: r(size(iu)), jac(size(iu), size(iu)), d(size(iu)), de_k(size(de))
    real(dp) :: r_prev(size(iu)), y(size(iu)), res_prev
    logical :: singular
    character(len=200) :: msg

    nu = size(iu)
    ncomp = size(de)
    t_new = pt%time + dt
    ! The stress scale: old stress, targets and the stress change the increment implies.
    scale = max(maxval(abs(pt%stress)), maxval(abs(target)), &
         c_el(1, 1) * maxval(abs(de)), tiny(1.0_dp))
    res = huge(1.0_dp)
    res_prev = huge(1.0_dp)
    r_prev = 0.0_dp
    d = 0.0_dp
    res_tol = 0.0_dp
    iterations = 0
    do iter = 1, path%max_iterations
       iterations = iter
       ! Perturbation: small against the increment and against the elastic strain of the
       ! stress level, large against round-off (differences of O(scale) numbers).
       h = fd_relative_step * max(maxval(abs(de)), scale / c_el(1, 1))
       call blk%set_point(1, mat%density, pt%strain, de, pt%stress, pt%state, &
            pt%field, pt%ener_intern, pt%ener_inelas)
       do j = 1, nu
          de_k = de
          de_k(iu(j)) = de_k(iu(j)) + h
          call blk%set_point(1 + j, mat%density, pt%strain, de_k, pt%stress, pt%state, &
               pt%field, pt%ener_intern, pt%ener_inelas)
       end do
       call blk%set_temperature(path%temperature_at(pt%time), path%temperature_at(t_new))
       call blk%call_material(mat, t_new, dt)
       if (.not. all_finite(blk%stress)) then
          call raise_error('', 0, 'the VUMAT returned a non-finite stress', err)
          return
       end if
       if (nu == 0) exit
       r = blk%stress(1, iu) - target
       res = maxval(abs(r))
       res_tol = path%tolerance * max(scale, maxval(abs(blk%stress(1, :))))
       if (res <= res_tol) exit
       if (iter == path%max_iterations) then
          write (msg, '(a,i0,a,es10.3,a,es10.3,a)') 'mixed control did not converge in ', &
               iter, ' iterations (stress residual ', res, ', tolerance ', res_tol, &
               '): the prescribed stresses may be beyond what the material can carry'
          call raise_error('', 0, trim(msg), err)
          return
       end if
       if (iter == 1 .or. res < fast_ratio * res_prev) then
          do j = 1, nu
             jac(:, j) = (blk%stress(1 + j, iu) - blk%stress(1, iu)) / h
          end do
       else
          ! Slow progress means the answer sits on a kink of the stress response (a
          ! Mohr-Coulomb edge or the elastic-plastic transition) where one-sided
          ! differences mislead. Broyden's update makes the Jacobian exact along the
          ! last step, which is the direction that matters on a piecewise-linear kink.
          y = r - r_prev
          jac = jac + spread(y - matmul(jac, d), 2, nu) * spread(d, 1, nu) / dot_product(d, d)
       end if
       r_prev = r
       res_prev = res
       call solve_dense(nu, jac, -r, d, singular, singular_tolerance)
       if (singular) then
          ! e.g. perfect plasticity: fall back to the elastic stiffness (which later
          ! Broyden updates then correct along the steps taken)
          jac = c_el(iu, iu)
          call solve_dense(nu, jac, -r, d, singular, singular_tolerance)
          if (singular) then
             call raise_error('', 0, 'mixed control: the elastic stiffness of the ' // &
                  'stress-controlled components ' // components_text(iu) // ' is singular', err)
             return
          end if
       end if
       de(iu) = de(iu) + d
    end do

    ! accept point 1
    pt%strain = pt%strain + de
    pt%stress = blk%stress(1, :)
    pt%state = blk%state(1, 1:mat%nstatev)
    pt%field = blk%field(1, 1:mat%nfieldv)
    pt%ener_intern = blk%ener_intern(1)
    pt%ener_inelas = blk%ener_inelas(1)
    pt%time = t_new
  end subroutine increment_newton

  pure logical function all_finite(a)
    real(dp), intent(in) :: a(:, :)

    all_finite = all(abs(a) <= huge(1.0_dp))
  end function all_finite

  pure function components_text(iu) result(text)
    integer, intent(in) :: iu(:)
    character(len=:), allocatable :: text
    integer :: j

    text = ''
    do j = 1, size(iu)
       if (j > 1) text = text // ','
       text = text // component_label(iu(j))
    end do
  end function components_text

  !> Prefix the recorded message with the stage (and increment) and locate it at the
  !> stage's file:line.
  subroutine stage_error(stage, s, inc, err)
    type(matpoint_stage_t), intent(in) :: stage
    integer, intent(in) :: s, inc
    type(error_t), intent(inout) :: err
    character(len=64) :: where
    character(len=:), allocatable :: file, text

    if (inc > 0) then
       write (where, '(a,i0,a,i0,a)') 'stage ', s, ', increment ', inc, ': '
    else
       write (where, '(a,i0,a)') 'stage ', s, ': '
    end if
    text = trim(where) // ' ' // err%message
    file = ''
    if (allocated(stage%file)) file = stage%file
    err%raised = .false.
    call raise_error(file, stage%line, text, err)
  end subroutine stage_error

end module matpoint_solver
