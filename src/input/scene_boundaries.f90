!> *BOUNDARY and Abaqus's propagation of boundary conditions between steps.
!>
!> The active conditions are kept per (node, dof) so that OP=MOD (the default) can replace
!> exactly the degrees of freedom a later line names, as Abaqus does, and OP=NEW can drop
!> everything before. At the end of each step the atoms are grouped back into
!> `boundary_t` entries (one per data line and dof range), which is what the solver gets.
!>
!> Data: node or node set, first dof[, last dof[, value]], or node/node set and one of
!> Abaqus's shorthands XSYMM (dof 1), YSYMM (2), ZSYMM (3), PINNED and ENCASTRE (all
!> translations; our continuum nodes have no rotations).
module scene_boundaries
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_block_t, data_line_t, is_integer_syntax
  use model, only: model_t
  use model_steps, only: boundary_t, bc_displacement, bc_velocity
  use model_amplitudes, only: amplitude_t
  use model_time_variation, only: time_variation_t, carry_into_step
  use scene_amplitudes, only: amplitude_param
  use scene_sets, only: node_targets
  use scene_util, only: itoa, get_int, get_real, field_name, last_field, expect_lines, &
       where_text, sort_permutation
  implicit none
  private

  public :: bc_state_t, bc_init, bc_clear, read_boundary, bc_resolve, boundary_op, bc_carry

  !> Active conditions as (node, dof) atoms; `owner(dof, node)` is the live atom or 0.
  type :: bc_state_t
     integer :: n = 0
     integer, allocatable :: node(:), dof(:), kind(:), src(:)
     real(dp), allocatable :: value(:)
     integer, allocatable :: owner(:, :)
     integer :: n_src = 0
     character(len=256), allocatable :: src_text(:)    !< file:line of each data line used
     type(time_variation_t), allocatable :: src_var(:)  !< time variation of each data line's conditions
  end type bc_state_t

contains

  subroutine bc_init(st, n_nodes)
    type(bc_state_t), intent(out) :: st
    integer, intent(in) :: n_nodes

    allocate (st%node(64), st%dof(64), st%kind(64), st%src(64), st%value(64))
    allocate (st%owner(3, n_nodes), st%src_text(16), st%src_var(16))
    st%owner = 0
  end subroutine bc_init

  !> At the start of a step: every condition carried over from the step before (`period` long,
  !> ending at total time `step_end`) follows Abaqus's rule for conditions not defined again
  !> (model_time_variation); conditions the step defines again replace their atoms afterwards.
  pure subroutine bc_carry(st, amplitudes, period, step_end)
    type(bc_state_t), intent(inout) :: st
    type(amplitude_t), intent(in) :: amplitudes(:)
    real(dp), intent(in) :: period, step_end
    integer :: k

    do k = 1, st%n_src
       call carry_into_step(st%src_var(k), amplitudes, period, step_end)
    end do
  end subroutine bc_carry

  !> OP=NEW: no condition stays active.
  subroutine bc_clear(st)
    type(bc_state_t), intent(inout) :: st

    st%n = 0
    st%owner = 0
  end subroutine bc_clear

  !> OP= of a *BOUNDARY: 'NEW' or 'MOD'.
  subroutine boundary_op(blk, op, err)
    type(keyword_block_t), intent(in) :: blk
    character(len=:), allocatable, intent(out) :: op
    type(error_t), intent(inout) :: err

    call blk%get_string('OP', op, err, default='MOD', choices=[character(len=3) :: 'MOD', 'NEW'])
  end subroutine boundary_op

  !> Add the conditions of one *BOUNDARY block. `in_step`: false for model data, where
  !> only zero displacements without amplitude are allowed (as in Abaqus).
  subroutine read_boundary(blk, model, in_step, st, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    logical, intent(in) :: in_step
    type(bc_state_t), intent(inout) :: st
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: btype, op, shorthand
    integer, allocatable :: nodes(:)
    integer :: il, kind, amp, first, last, ndim, nf
    real(dp) :: value

    ndim = model%mesh%ndim
    call blk%check_params([character(len=9) :: 'TYPE', 'AMPLITUDE', 'OP'], err)
    if (.not. err%raised) call blk%get_string('TYPE', btype, err, default='DISPLACEMENT', &
         choices=[character(len=12) :: 'DISPLACEMENT', 'VELOCITY'])
    if (.not. err%raised) call boundary_op(blk, op, err)
    if (.not. err%raised) call amplitude_param(blk, model, amp, err)
    if (err%raised) return
    kind = merge(bc_velocity, bc_displacement, btype == 'VELOCITY')
    if (.not. in_step .and. (kind /= bc_displacement .or. amp /= 0 .or. blk%has_param('OP'))) then
       call blk%fail('*BOUNDARY in model data takes no TYPE=VELOCITY, AMPLITUDE= or OP=; ' // &
            'expected them on a *BOUNDARY inside a step', err)
       return
    end if
    ! OP=NEW without data lines removes every boundary condition (Abaqus)
    call expect_lines(blk, merge(0, 1, op == 'NEW'), huge(1), &
         'node or node set, first dof[, last dof[, value]]', err)
    if (err%raised) return
    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         nf = last_field(dl)
         if (nf < 2 .or. nf > 4) then
            call raise_error(dl%file, dl%line, itoa(nf) // ' values on a *BOUNDARY line; expected ' // &
                 'node or node set, first dof[, last dof[, value]] or node, XSYMM|YSYMM|ZSYMM|PINNED|ENCASTRE', err)
            return
         end if
         call node_targets(model, dl, 1, nodes, err)
         if (err%raised) return
         value = 0
         shorthand = field_name(dl, 2)
         if (.not. is_integer_syntax(shorthand)) then
            if (nf > 2) then
               call raise_error(dl%file, dl%line, 'data beyond what *BOUNDARY takes after ' // &
                    shorthand // '; expected node or node set, ' // shorthand, err)
               return
            end if
            if (kind == bc_velocity) then
               call raise_error(dl%file, dl%line, shorthand // ' with TYPE=VELOCITY; expected dof ' // &
                    'numbers and a velocity', err)
               return
            end if
            select case (shorthand)
            case ('XSYMM'); first = 1; last = 1
            case ('YSYMM'); first = 2; last = 2
            case ('ZSYMM'); first = 3; last = 3
            case ('PINNED', 'ENCASTRE'); first = 1; last = ndim
            case ('XASYMM', 'YASYMM', 'ZASYMM')
               ! antisymmetry about a plane x, y or z = const: the two in-plane translations held
               ! (the rotation about the normal: none on our nodes)
               call antisymmetry(shorthand, ndim, first, last)
               if (shorthand == 'YASYMM' .and. ndim == 3) then
                  call add_atoms(st, nodes, 1, 1, kind, value, amp, where_text(dl%file, dl%line))
                  first = 3
                  last = 3
               end if
            case default
               call raise_error(dl%file, dl%line, 'boundary type "' // dl%field(2) // '" is not ' // &
                    'supported; expected a dof number or XSYMM, YSYMM, ZSYMM, XASYMM, YASYMM, ZASYMM, ' // &
                    'PINNED, ENCASTRE', err)
               return
            end select
         else
            call get_int(dl, 2, first, err)
            if (.not. err%raised) call get_int(dl, 3, last, err, default=first)
            if (.not. err%raised) call get_real(dl, 4, value, err, default=0.0_dp)
            if (err%raised) return
         end if
         if (first >= 1 .and. last >= first .and. last > ndim .and. last <= 6) then
            ! dofs beyond the translations: only on rigid-body reference nodes, only held
            if (all_reference_nodes(model, nodes)) then
               call held_rotations(model, dl, first, last, value, err)
               if (err%raised) return
               if (first > ndim) cycle
               last = ndim
            end if
         end if
         if (first < 1 .or. last < first .or. last > ndim) then
            call raise_error(dl%file, dl%line, 'degrees of freedom ' // itoa(first) // '..' // itoa(last) // &
                 ' are not translations of this ' // itoa(ndim) // 'D model; expected 1 <= first <= last <= ' // &
                 itoa(ndim) // ' (up to 6 on a *RIGID BODY reference node, rotations held)', err)
            return
         end if
         if (.not. in_step .and. abs(value) > 0) then
            call raise_error(dl%file, dl%line, 'non-zero value in a model-data *BOUNDARY; expected ' // &
                 'prescribed values on a *BOUNDARY inside a step', err)
            return
         end if
         call add_atoms(st, nodes, first, last, kind, value, amp, where_text(dl%file, dl%line))
       end associate
    end do
  end subroutine read_boundary

  !> XASYMM, YASYMM, ZASYMM: the translations in the plane of antisymmetry (YASYMM in 3D is
  !> dofs 1 and 3: the caller adds dof 1 and this gives 3).
  pure subroutine antisymmetry(shorthand, ndim, first, last)
    character(len=*), intent(in) :: shorthand
    integer, intent(in) :: ndim
    integer, intent(out) :: first, last

    select case (shorthand)
    case ('XASYMM')
       first = 2
       last = ndim
    case ('YASYMM')
       first = 1
       last = 1
    case default
       first = 1
       last = 2
    end select
  end subroutine antisymmetry

  !> Every node is the reference node of a *RIGID BODY.
  pure logical function all_reference_nodes(model, nodes)
    type(model_t), intent(in) :: model
    integer, intent(in) :: nodes(:)
    integer :: j

    all_reference_nodes = size(nodes) > 0
    do j = 1, size(nodes)
       if (.not. any(model%rigid_surfaces(1:model%n_rigid_surfaces)%ref_node == nodes(j))) then
          all_reference_nodes = .false.
          return
       end if
    end do
  end function all_reference_nodes

  !> dofs beyond ndim on reference nodes: Abaqus's rotations (4..6; and 3 of a 2D reference
  !> node). Our rigid bodies translate only, so their rotations are held already: accepted with
  !> a zero value, refused otherwise.
  subroutine held_rotations(model, dl, first, last, value, err)
    type(model_t), intent(in) :: model
    type(data_line_t), intent(in) :: dl
    integer, intent(in) :: first, last
    real(dp), intent(in) :: value
    type(error_t), intent(inout) :: err

    if (abs(value) > 0) then
       call raise_error(dl%file, dl%line, 'a non-zero value on dofs ' // itoa(first) // '..' // itoa(last) // &
            ' of a rigid-body reference node: rigid-body rotation is not simulated (our rigid walls ' // &
            'translate); expected 0 (held) or dofs 1..' // itoa(model%mesh%ndim), err)
    end if
  end subroutine held_rotations

  !> OP=MOD semantics: a (node, dof) named again gets the new condition.
  subroutine add_atoms(st, nodes, first, last, kind, value, amp, source)
    type(bc_state_t), intent(inout) :: st
    integer, intent(in) :: nodes(:), first, last, kind, amp
    real(dp), intent(in) :: value
    character(len=*), intent(in) :: source
    character(len=256), allocatable :: ttmp(:)
    type(time_variation_t), allocatable :: vtmp(:)
    integer :: i, d

    if (st%n_src >= size(st%src_text)) then
       allocate (ttmp(2 * size(st%src_text)), vtmp(2 * size(st%src_text)))
       ttmp(1:st%n_src) = st%src_text(1:st%n_src)
       vtmp(1:st%n_src) = st%src_var(1:st%n_src)
       call move_alloc(ttmp, st%src_text)
       call move_alloc(vtmp, st%src_var)
    end if
    st%n_src = st%n_src + 1
    st%src_text(st%n_src) = source
    st%src_var(st%n_src) = time_variation_t(amplitude=amp)
    call compact(st)
    do d = first, last
       do i = 1, size(nodes)
          if (st%owner(d, nodes(i)) /= 0) st%kind(st%owner(d, nodes(i))) = 0   ! superseded
          call grow(st)
          st%n = st%n + 1
          st%node(st%n) = nodes(i)
          st%dof(st%n) = d
          st%kind(st%n) = kind
          st%value(st%n) = value
          st%src(st%n) = st%n_src
          st%owner(d, nodes(i)) = st%n
       end do
    end do
  end subroutine add_atoms

  !> Drop superseded atoms (kind 0) when they make up half the list.
  subroutine compact(st)
    type(bc_state_t), intent(inout) :: st
    integer :: i, m

    if (count(st%kind(1:st%n) == 0) * 2 < st%n .or. st%n < 64) return
    m = 0
    do i = 1, st%n
       if (st%kind(i) == 0) cycle
       m = m + 1
       st%node(m) = st%node(i)
       st%dof(m) = st%dof(i)
       st%kind(m) = st%kind(i)
       st%value(m) = st%value(i)
       st%src(m) = st%src(i)
       st%owner(st%dof(m), st%node(m)) = m
    end do
    st%n = m
  end subroutine compact

  subroutine grow(st)
    type(bc_state_t), intent(inout) :: st
    integer :: m

    if (st%n < size(st%node)) return
    m = 2 * size(st%node)
    call grow_int(st%node, m)
    call grow_int(st%dof, m)
    call grow_int(st%kind, m)
    call grow_int(st%src, m)
    block
      real(dp), allocatable :: tmp(:)
      allocate (tmp(m))
      tmp(1:st%n) = st%value(1:st%n)
      call move_alloc(tmp, st%value)
    end block
  end subroutine grow

  subroutine grow_int(a, m)
    integer, allocatable, intent(inout) :: a(:)
    integer, intent(in) :: m
    integer, allocatable :: tmp(:)

    allocate (tmp(m))
    tmp(1:size(a)) = a
    call move_alloc(tmp, a)
  end subroutine grow_int

  !> The active conditions as boundary_t entries: one per data line and dof, merged into
  !> a dof range when consecutive dofs of a line hold the same nodes.
  subroutine bc_resolve(st, boundaries)
    type(bc_state_t), intent(in) :: st
    type(boundary_t), allocatable, intent(out) :: boundaries(:)
    integer, allocatable :: live(:), keys(:), perm(:), bsrc(:)
    type(boundary_t), allocatable :: list(:)
    integer :: i, j, k, n, nb, a

    n = count(st%kind(1:st%n) /= 0)
    allocate (live(n), keys(n), list(n), bsrc(n))
    k = 0
    do i = 1, st%n
       if (st%kind(i) == 0) cycle
       k = k + 1
       live(k) = i
       keys(k) = 4 * st%src(i) + st%dof(i)
    end do
    call sort_permutation(keys, perm)
    nb = 0
    i = 1
    do while (i <= n)
       j = i
       do while (j < n)
          if (keys(perm(j + 1)) /= keys(perm(i))) exit
          j = j + 1
       end do
       a = live(perm(i))
       ! atoms i..j share the data line and dof; nodes ascend (added in set order)
       nb = nb + 1
       allocate (list(nb)%nodes(j - i + 1))
       do k = i, j
          list(nb)%nodes(k - i + 1) = st%node(live(perm(k)))
       end do
       list(nb)%first_dof = st%dof(a)
       list(nb)%last_dof = st%dof(a)
       list(nb)%kind = st%kind(a)
       list(nb)%value = st%value(a)
       list(nb)%variation = st%src_var(st%src(a))
       list(nb)%source = st%src_text(st%src(a))
       bsrc(nb) = st%src(a)
       if (nb > 1) then
          if (bsrc(nb - 1) == bsrc(nb) .and. list(nb - 1)%last_dof + 1 == list(nb)%first_dof &
               .and. size(list(nb - 1)%nodes) == size(list(nb)%nodes)) then
             if (all(list(nb - 1)%nodes == list(nb)%nodes)) then
                list(nb - 1)%last_dof = list(nb)%first_dof
                deallocate (list(nb)%nodes)
                nb = nb - 1
             end if
          end if
       end if
       i = j + 1
    end do
    allocate (boundaries(nb))
    do k = 1, nb
       boundaries(k) = list(k)
    end do
  end subroutine bc_resolve
end module scene_boundaries
