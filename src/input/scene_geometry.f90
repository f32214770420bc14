!> The element geometry of a scene, checked before the first increment (so `--check` finds it):
!> two nodes of an element at one point, a zero area or volume, an inverted element (nodes in
!> the wrong order) and a tangled (bow-tie) one. Each of these would otherwise stop the run at
!> its first increment (the run's inversion check) or, with a zero area, divide by zero there.
!>
!> The tests are those of the run (fem_inversion: the one-point volume and every corner
!> Jacobian of the reference configuration), so a mesh --check accepts passes increment 1's
!> check too. "Zero" is relative: |V| below 1e-12 of the cube (square) of the element's longest
!> edge, well below any mesh a solver can integrate.
module scene_geometry
  use, intrinsic :: iso_fortran_env, only: int64
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t
  use model, only: model_t
  use scene_mesh, only: mesh_sources_t
  use model_mesh, only: element_cax4r
  use scene_util, only: itoa, rtoa
  use fem_cpe4r, only: cpe4r_geometry
  use fem_c3d8r, only: c3d8r_geometry
  use fem_inversion, only: check_inversion, inversion_centre, inversion_corner
  implicit none
  private

  public :: check_element_geometry

  integer, parameter :: chunk = 256
  real(dp), parameter :: zero_volume_ratio = 1.0e-12_dp

contains

  !> The first bad element (by element number), at the file:line of its definition.
  subroutine check_element_geometry(deck, model, sources, err)
    type(keyword_deck_t), intent(in) :: deck
    type(model_t), intent(in) :: model
    type(mesh_sources_t), intent(in) :: sources
    type(error_t), intent(inout) :: err
    real(dp), allocatable :: xe(:, :, :), volume(:), bmat(:, :, :), size_of(:)
    integer, allocatable :: reason(:)
    integer :: e0, nb, e, a, b, nd, ne, ie
    character(len=:), allocatable :: problem

    nd = model%mesh%ndim
    ne = model%mesh%nen
    ! The run's node-to-element lists hold n_elems × nen entries with 32-bit counts: a mesh
    ! beyond them is refused here rather than overflowing there.
    if (int(model%mesh%n_elems, int64) * ne > huge(1)) then
       associate (blk => deck%blocks(sources%elem_block(1)))
         call raise_error(blk%file, blk%line, 'the mesh has ' // itoa(model%mesh%n_elems) // ' elements of ' // &
              itoa(ne) // ' nodes: more element-node entries than the 2147483647 a run indexes; expected ' // &
              'a smaller mesh', err)
       end associate
       return
    end if
    allocate (xe(chunk, nd, ne), volume(chunk), bmat(chunk, nd, ne), reason(chunk), size_of(chunk))
    do e0 = 1, model%mesh%n_elems, chunk
       nb = min(chunk, model%mesh%n_elems - e0 + 1)
       ! Each element moved to its node 1 and scaled by 1/(4 h), h its largest node distance:
       ! the geometry kernels divide by the volume (guarded by tiny), and on this scale even a
       ! zero volume gives finite gradients (no overflow trap in the debug build).
       do e = 1, nb
          ie = e0 + e - 1
          size_of(e) = 0
          do b = 2, ne
             do a = 1, b - 1
                size_of(e) = max(size_of(e), norm2(model%mesh%x0(:, model%mesh%conn(a, ie)) - &
                     model%mesh%x0(:, model%mesh%conn(b, ie))))
             end do
          end do
          do a = 1, ne
             xe(e, :, a) = (model%mesh%x0(:, model%mesh%conn(a, ie)) - model%mesh%x0(:, model%mesh%conn(1, ie))) &
                  / (4 * max(size_of(e), tiny(1.0_dp)))
          end do
       end do
       if (nd == 2) then
          call cpe4r_geometry(nb, xe(1:nb, :, :), 1.0_dp, volume(1:nb), bmat(1:nb, :, :))
       else
          call c3d8r_geometry(nb, xe(1:nb, :, :), volume(1:nb), bmat(1:nb, :, :))
       end if
       call check_inversion(nb, nd, ne, xe(1:nb, :, :), volume(1:nb), volume(1:nb), 0.0_dp, reason(1:nb))
       do e = 1, nb
          ie = e0 + e - 1
          problem = element_problem(model, ie, volume(e), size_of(e), reason(e))
          if (len(problem) == 0) cycle
          associate (dl => deck%blocks(sources%elem_block(ie))%lines(sources%elem_line(ie)))
            call raise_error(dl%file, dl%line, 'element ' // itoa(model%mesh%elem_id(ie)) // ' ' // &
                 problem, err)
          end associate
          return
       end do
    end do
  end subroutine check_element_geometry

  !> '' for a good element, else what is wrong and what was expected. scaled_volume: the volume
  !> of the element scaled by 1/(4 h) (h = size, its largest node distance).
  function element_problem(model, ie, scaled_volume, size, reason) result(text)
    type(model_t), intent(in) :: model
    integer, intent(in) :: ie
    real(dp), intent(in) :: scaled_volume, size
    integer, intent(in) :: reason
    character(len=:), allocatable :: text
    integer :: a, b, nd, ne
    real(dp) :: volume
    character(len=6) :: what

    text = ''
    nd = model%mesh%ndim
    ne = model%mesh%nen
    what = merge('area  ', 'volume', nd == 2)
    associate (x => model%mesh%x0, conn => model%mesh%conn)
      if (model%mesh%element_type == element_cax4r) then
         do a = 1, ne
            if (x(1, conn(a, ie)) < 0.0_dp) then
               text = 'has its node ' // itoa(model%mesh%node_id(conn(a, ie))) // ' at r = ' // &
                    rtoa(x(1, conn(a, ie))) // ' < 0 (below the symmetry axis); expected every node of ' // &
                    'an axisymmetric (CAX4R) element at r = x >= 0 (nodes on the axis r = 0 are allowed)'
               return
            end if
         end do
      end if
      do b = 2, ne
         do a = 1, b - 1
            if (maxval(abs(x(:, conn(a, ie)) - x(:, conn(b, ie)))) <= 0.0_dp) then
               text = 'has its nodes ' // itoa(model%mesh%node_id(conn(a, ie))) // ' and ' // &
                    itoa(model%mesh%node_id(conn(b, ie))) // ' at the same point (' // &
                    point_text(x(:, conn(a, ie))) // '); expected ' // itoa(ne) // ' nodes at distinct ' // &
                    'points (a collapsed element is not supported)'
               return
            end if
         end do
      end do
    end associate
    volume = scaled_volume * (4 * size)**nd
    if (abs(scaled_volume) <= zero_volume_ratio / 4.0_dp**nd) then
       text = 'has zero ' // trim(what) // ' (' // rtoa(volume) // ' for a size of ' // rtoa(size) // &
            '); expected an element with a positive ' // trim(what) // ' and ' // node_order(nd)
    else if (reason == inversion_centre) then
       text = 'is inverted (' // trim(what) // ' ' // rtoa(volume) // ' < 0): its nodes are in the wrong ' // &
            'order; expected ' // node_order(nd)
    else if (reason == inversion_corner) then
       text = 'is tangled (a bow-tie or folded element: a corner Jacobian <= 0 although the ' // trim(what) // &
            ' is ' // rtoa(volume) // '); expected a convex element with ' // node_order(nd)
    end if
  end function element_problem

  pure function node_order(nd) result(text)
    integer, intent(in) :: nd
    character(len=:), allocatable :: text

    if (nd == 2) then
       text = 'the nodes counter-clockwise around the element (Abaqus order)'
    else
       text = 'nodes 1-4 counter-clockwise seen from nodes 5-8 above them (Abaqus order)'
    end if
  end function node_order

  function point_text(x) result(text)
    real(dp), intent(in) :: x(:)
    character(len=:), allocatable :: text
    integer :: k

    text = rtoa(x(1))
    do k = 2, size(x)
       text = text // ', ' // rtoa(x(k))
    end do
  end function point_text
end module scene_geometry
