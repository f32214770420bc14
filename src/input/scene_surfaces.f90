!> Surfaces and rigid bodies of a scene.
!>
!> * *SURFACE, TYPE=ELEMENT (Abaqus's default): element or element set, face S1..S4 (CPE4R)
!>   or S1..S6 (C3D8R), with Abaqus's face numbering; the face nodes are collected.
!> * *SURFACE, TYPE=SEGMENTS (2D analytic rigid surface): START, x, y then LINE, x, y and
!>   CIRCL, x, y, xc, yc (end point and centre; the arc is the one under 180 degrees).
!> * *SURFACE, TYPE=PLANE (bulkflow's, 3D analytic rigid surface): a point line x, y, z and
!>   a normal line nx, ny, nz; the material lies on the side the normal points to.
!> * *SURFACE, TYPE=CYLINDER / TYPE=REVOLUTION (3D analytic rigid surfaces, Abaqus's): the local
!>   system's points a, b (and c) on one (two) lines, omitted inside a part, then the profile as
!>   for SEGMENTS, in local (x, y) or (r, z) coordinates (read_swept).
!> * *SURFACE, TYPE=FACETS (bulkflow's; what R3D3/R3D4 walls become): scene_facet_surface.
!> * *RIGID BODY, REF NODE=..., ANALYTICAL SURFACE=...: the surface moves with that node.
!>
!> Element and rigid surfaces share one namespace, as in Abaqus.
module scene_surfaces
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t, data_line_t, is_integer_text
  use model, only: model_t
  use model_sets, only: find_set, name_length
  use model_surfaces, only: element_surface_t, rigid_surface_t, segment_t, segment_line, segment_arc, &
       cpe4r_faces, c3d8r_faces, shape_cylinder, shape_revolution
  use scene_facet_surface, only: read_facets
  use contact_geometry, only: segment_closest_point
  use scene_layout, only: scene_layout_t
  use scene_sets, only: elem_targets
  use scene_util, only: itoa, rtoa, get_real, field_name, expect_fields, expect_lines, &
       append_int, sort_unique, sort_permutation, check_name
  implicit none
  private

  public :: build_surfaces, build_rigid_bodies, find_element_surface, find_rigid_surface, require_element_surface


  !> Relative tolerance on the two radii of a CIRCL segment (coordinates typed with a
  !> few digits, e.g. 0.7071 for sqrt(1/2), must pass).
  real(dp), parameter :: radius_tolerance = 1.0e-4_dp

contains

  pure integer function find_element_surface(model, name)
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: name
    integer :: k

    find_element_surface = 0
    do k = 1, model%n_element_surfaces
       if (model%element_surfaces(k)%name == name) then
          find_element_surface = k
          return
       end if
    end do
  end function find_element_surface

  pure integer function find_rigid_surface(model, name)
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: name
    integer :: k

    find_rigid_surface = 0
    do k = 1, model%n_rigid_surfaces
       if (model%rigid_surfaces(k)%name == name) then
          find_rigid_surface = k
          return
       end if
    end do
  end function find_rigid_surface

  subroutine build_surfaces(deck, layout, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    type(element_surface_t), allocatable :: etmp(:)
    type(rigid_surface_t), allocatable :: rtmp(:)
    character(len=:), allocatable :: name, stype
    integer :: i

    allocate (model%element_surfaces(0), model%rigid_surfaces(0))
    model%n_element_surfaces = 0
    model%n_rigid_surfaces = 0
    do i = 1, deck%n_blocks
       if (layout%step_of(i) /= 0 .or. deck%blocks(i)%name /= 'SURFACE') cycle
       associate (blk => deck%blocks(i))
         call blk%check_params([character(len=8) :: 'NAME', 'TYPE', 'INTERNAL'], err)
         if (err%raised) return
         call blk%get_string('NAME', name, err)
         if (.not. err%raised) call blk%get_string('TYPE', stype, err, default='ELEMENT', &
              choices=[character(len=10) :: 'ELEMENT', 'SEGMENTS', 'PLANE', 'CYLINDER', 'REVOLUTION', 'FACETS'])
         if (.not. err%raised) call check_name(blk, 'surface', name, name_length, err)
         if (err%raised) return
         if (find_element_surface(model, name) /= 0 .or. find_rigid_surface(model, name) /= 0) then
            call blk%fail('surface ' // name // ' defined twice; expected unique surface names', err)
            return
         end if
         if (stype == 'ELEMENT') then
            allocate (etmp(model%n_element_surfaces + 1))
            etmp(1:model%n_element_surfaces) = model%element_surfaces
            call move_alloc(etmp, model%element_surfaces)
            model%n_element_surfaces = model%n_element_surfaces + 1
            model%element_surfaces(model%n_element_surfaces)%name = name
            call read_element_surface(blk, model, model%n_element_surfaces, err)
         else
            allocate (rtmp(model%n_rigid_surfaces + 1))
            rtmp(1:model%n_rigid_surfaces) = model%rigid_surfaces
            call move_alloc(rtmp, model%rigid_surfaces)
            model%n_rigid_surfaces = model%n_rigid_surfaces + 1
            associate (rs => model%rigid_surfaces(model%n_rigid_surfaces))
              rs%name = name
              rs%ndim = model%mesh%ndim
              select case (stype)
              case ('SEGMENTS')
                 call read_segments(blk, model%mesh%ndim, rs, err)
              case ('CYLINDER', 'REVOLUTION')
                 call read_swept(blk, stype, model%mesh%ndim, rs, err)
              case ('FACETS')
                 call read_facets(blk, model%mesh%ndim, rs, err)
              case default
                 call read_plane(blk, model%mesh%ndim, rs, err)
              end select
            end associate
         end if
         if (err%raised) return
       end associate
    end do
  end subroutine build_surfaces

  subroutine read_element_surface(blk, model, ks, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(inout) :: model
    integer, intent(in) :: ks
    type(error_t), intent(inout) :: err
    integer, allocatable :: elems(:), faces(:), targets(:), nodes(:), keys(:), perm(:)
    integer, allocatable :: ue(:), uf(:)
    character(len=:), allocatable :: face
    integer :: il, j, n, nn, nfaces, f, ios, k, nu, nen_face

    nfaces = merge(4, 6, model%mesh%ndim == 2)
    nen_face = merge(2, 4, model%mesh%ndim == 2)
    call expect_lines(blk, 1, huge(1), 'element or element set, face S1..S' // itoa(nfaces), err)
    if (err%raised) return
    n = 0
    nn = 0
    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         call expect_fields(blk, dl, 2, 2, 'element or element set, face S1..S' // itoa(nfaces), err)
         if (err%raised) return
         call elem_targets(model, dl, 1, targets, err)
         if (err%raised) return
         face = field_name(dl, 2)
         f = 0
         ios = 1
         if (len(face) >= 2) then
            if (face(1:1) == 'S' .and. is_integer_text(face(2:))) read (face(2:), *, iostat=ios) f
         end if
         if (ios /= 0 .or. f < 1 .or. f > nfaces) then
            call raise_error(dl%file, dl%line, 'face "' // dl%field(2) // '" is not a face of ' // &
                 trim(merge('CPE4R', 'C3D8R', nfaces == 4)) // '; expected S1..S' // itoa(nfaces), err)
            return
         end if
         do j = 1, size(targets)
            call append_int(elems, n, targets(j))
            call append_int(faces, nn, f)
         end do
       end associate
    end do
    if (n == 0) then
       call blk%fail('surface has no faces (its element sets are empty); expected at least ' // &
            'one element face', err)
       return
    end if
    ! distinct (element, face) pairs in element order
    allocate (keys(n))
    keys = (elems(1:n) - 1) * 8 + faces(1:n)
    call sort_permutation(keys, perm)
    allocate (ue(n), uf(n))
    nu = 0
    do j = 1, n
       if (nu > 0) then
          if (ue(nu) == elems(perm(j)) .and. uf(nu) == faces(perm(j))) cycle
       end if
       nu = nu + 1
       ue(nu) = elems(perm(j))
       uf(nu) = faces(perm(j))
    end do
    allocate (nodes(nu * nen_face))
    do j = 1, nu
       do k = 1, nen_face
          if (nfaces == 4) then
             nodes((j - 1) * nen_face + k) = model%mesh%conn(cpe4r_faces(k, uf(j)), ue(j))
          else
             nodes((j - 1) * nen_face + k) = model%mesh%conn(c3d8r_faces(k, uf(j)), ue(j))
          end if
       end do
    end do
    associate (s => model%element_surfaces(ks))
      s%elems = ue(1:nu)
      s%faces = uf(1:nu)
      call sort_unique(nodes, s%nodes)
    end associate
  end subroutine read_element_surface

  !> START / LINE / CIRCL chain of a 2D analytic rigid surface; from line `first` on (present:
  !> the profile of a CYLINDER or REVOLUTION surface, whatever ndim).
  subroutine read_segments(blk, ndim, rs, err, first)
    type(keyword_block_t), intent(in) :: blk
    integer, intent(in) :: ndim
    type(rigid_surface_t), intent(inout) :: rs
    type(error_t), intent(inout) :: err
    integer, intent(in), optional :: first
    character(len=:), allocatable :: kind
    real(dp) :: p(2), c(2), r0, r1, cross, dot
    integer :: il, n, il0

    il0 = 1
    if (present(first)) then
       il0 = first
    else if (ndim /= 2) then
       call blk%fail('*SURFACE, TYPE=SEGMENTS in a 3D model; expected TYPE=PLANE, CYLINDER or REVOLUTION ' // &
            'for a 3D wall', err)
       return
    end if
    call expect_lines(blk, il0 + 1, huge(1), 'START, x, y then LINE, x, y or CIRCL, x, y, xc, yc lines', err)
    if (err%raised) return
    allocate (rs%segments(blk%n_lines - il0))
    n = 0
    do il = il0, blk%n_lines
       associate (dl => blk%lines(il))
         kind = field_name(dl, 1)
         if (il == il0 .neqv. kind == 'START') then
            call raise_error(dl%file, dl%line, 'segment "' // dl%field(1) // '" here; expected ' // &
                 trim(merge('START, x, y as the first line     ', 'LINE or CIRCL after the START line', il == il0)), err)
            return
         end if
         select case (kind)
         case ('START', 'LINE')
            call expect_fields(blk, dl, 3, 3, kind // ', x, y', err)
         case ('CIRCL')
            call expect_fields(blk, dl, 5, 5, 'CIRCL, x, y, xc, yc (end point, centre)', err)
         case default
            call raise_error(dl%file, dl%line, 'unknown segment type "' // dl%field(1) // &
                 '"; expected START, LINE or CIRCL', err)
         end select
         if (err%raised) return
         call get_real(dl, 2, p(1), err)
         if (.not. err%raised) call get_real(dl, 3, p(2), err)
         if (err%raised) return
         if (kind == 'START') then
            rs%point(1:2) = p
            cycle
         end if
         n = n + 1
         associate (seg => rs%segments(n))
           if (n == 1) then
              seg%p0 = rs%point(1:2)
           else
              seg%p0 = rs%segments(n - 1)%p1
           end if
           seg%p1 = p
           if (.not. (norm2(seg%p1 - seg%p0) > 0)) then
              call raise_error(dl%file, dl%line, 'segment of zero length (end point equals start); ' // &
                   'expected a distinct end point', err)
              return
           end if
           if (kind == 'LINE') then
              seg%kind = segment_line
              cycle
           end if
           seg%kind = segment_arc
           call get_real(dl, 4, c(1), err)
           if (.not. err%raised) call get_real(dl, 5, c(2), err)
           if (err%raised) return
           seg%centre = c
           r0 = norm2(seg%p0 - c)
           r1 = norm2(seg%p1 - c)
           if (.not. (r0 > 0 .and. r1 > 0) .or. abs(r0 - r1) > radius_tolerance * max(r0, r1)) then
              call raise_error(dl%file, dl%line, 'CIRCL start and end are not equidistant from the ' // &
                   'centre (radii ' // rtoa(r0) // ' and ' // rtoa(r1) // &
                   '); expected both points on one circle about (xc, yc)', err)
              return
           end if
           cross = (seg%p0(1) - c(1)) * (seg%p1(2) - c(2)) - (seg%p0(2) - c(2)) * (seg%p1(1) - c(1))
           dot = dot_product(seg%p0 - c, seg%p1 - c)
           if (dot < 0 .and. abs(cross) <= 1.0e-9_dp * r0 * r1) then
              call raise_error(dl%file, dl%line, 'CIRCL spans 180 degrees, so its direction is ' // &
                   'ambiguous; expected an arc under 180 degrees (split it in two)', err)
              return
           end if
         end associate
       end associate
    end do
    rs%n_segments = n
  end subroutine read_segments

  !> TYPE=CYLINDER: line 1 a, b (origin, a point on the local x axis), line 2 c (a point on the
  !> generator, the local z axis), then the (x, y) profile. TYPE=REVOLUTION: line 1 a, b (a point on
  !> the symmetry axis, the local z axis), then the (r, z) profile, r >= 0. Omitted system lines
  !> (Abaqus/CAE inside a part): a = 0, b = (1, 0, 0), c = (0, 0, 1) for CYLINDER; a = 0, b = (0, 1, 0)
  !> for REVOLUTION (CAE revolves about the part's y axis). The x axis of a CYLINDER is made normal to
  !> the generator (b's component along it is dropped).
  subroutine read_swept(blk, stype, ndim, rs, err)
    type(keyword_block_t), intent(in) :: blk
    character(len=*), intent(in) :: stype
    integer, intent(in) :: ndim
    type(rigid_surface_t), intent(inout) :: rs
    type(error_t), intent(inout) :: err
    real(dp) :: a(3), b(3), c(3), ez(3), ex(3), length
    integer :: n_system, k

    if (ndim /= 3) then
       call blk%fail('*SURFACE, TYPE=' // stype // ' in a 2D model; expected TYPE=SEGMENTS for a 2D wall', err)
       return
    end if
    call expect_lines(blk, 1, huge(1), 'the local system a, b' // trim(merge(' (line 2: c)', '            ', &
         stype == 'CYLINDER')) // ' then START, LINE and CIRCL profile lines', err)
    if (err%raised) return
    n_system = merge(2, 1, stype == 'CYLINDER')
    a = 0
    b = [0.0_dp, 1.0_dp, 0.0_dp]
    c = [0.0_dp, 0.0_dp, 1.0_dp]
    if (stype == 'CYLINDER') b = [1.0_dp, 0.0_dp, 0.0_dp]
    if (field_name(blk%lines(1), 1) == 'START') then
       n_system = 0
    else
       call expect_fields(blk, blk%lines(1), 6, 6, 'x, y, z of a then of b', err)
       if (.not. err%raised .and. n_system == 2) then
          call expect_lines(blk, 2, huge(1), 'line 2: x, y, z of c, a point on the generator', err)
          if (.not. err%raised) call expect_fields(blk, blk%lines(2), 3, 3, 'x, y, z of c, a point on the generator', err)
       end if
       do k = 1, 3
          if (err%raised) return
          call get_real(blk%lines(1), k, a(k), err)
          if (.not. err%raised) call get_real(blk%lines(1), k + 3, b(k), err)
          if (.not. err%raised .and. n_system == 2) call get_real(blk%lines(2), k, c(k), err)
       end do
       if (err%raised) return
    end if
    if (stype == 'CYLINDER') then
       rs%shape = shape_cylinder
       ez = c - a
       ex = b - a
    else
       rs%shape = shape_revolution
       ez = b - a
       ex = [1.0_dp, 0.0_dp, 0.0_dp]
       if (abs(ez(1)) > max(abs(ez(2)), abs(ez(3)))) ex = [0.0_dp, 1.0_dp, 0.0_dp]
    end if
    length = norm2(ez)
    if (.not. (length > 0)) then
       call raise_error(blk%lines(n_system)%file, blk%lines(n_system)%line, 'the ' // &
            trim(merge('generator point c', 'axis point b     ', stype == 'CYLINDER')) // ' equals the origin a; ' // &
            'expected a distinct point to give the ' // trim(merge('generator', 'axis     ', stype == 'CYLINDER')), err)
       return
    end if
    ez = ez / length
    ex = ex - dot_product(ex, ez) * ez
    if (.not. (norm2(ex) > 1.0e-6_dp * norm2(b - a))) then
       call raise_error(blk%lines(1)%file, blk%lines(1)%line, 'the local x axis (a to b) is along the ' // &
            'generator (a to c); expected b off the generator line', err)
       return
    end if
    rs%axes(:, 1) = ex / norm2(ex)
    rs%axes(:, 3) = ez
    rs%axes(:, 2) = [ez(2) * rs%axes(3, 1) - ez(3) * rs%axes(2, 1), ez(3) * rs%axes(1, 1) - ez(1) * rs%axes(3, 1), &
         ez(1) * rs%axes(2, 1) - ez(2) * rs%axes(1, 1)]
    call read_segments(blk, ndim, rs, err, first=n_system + 1)
    rs%point = a   ! read_segments keeps the START point there
    if (err%raised .or. stype /= 'REVOLUTION') return
    do k = 1, rs%n_segments
       if (min(rs%segments(k)%p0(1), rs%segments(k)%p1(1), arc_least_r(rs%segments(k))) < 0) then
          call raise_error(blk%lines(n_system + 1 + k)%file, blk%lines(n_system + 1 + k)%line, 'profile point ' // &
               'at r < 0; expected the (r, z) profile of a TYPE=REVOLUTION surface at r >= 0', err)
          return
       end if
    end do
  end subroutine read_swept

  !> Smallest r of an arc's interior: its leftmost circle point if the arc passes through it (then
  !> it is the arc's closest point to a point far to the left), else its end points; lines: huge.
  pure real(dp) function arc_least_r(seg) result(r)
    type(segment_t), intent(in) :: seg
    real(dp) :: radius, cp(2), normal(2), dist
    integer :: where

    r = huge(1.0_dp)
    if (seg%kind /= segment_arc) return
    radius = norm2(seg%p0 - seg%centre)
    call segment_closest_point(seg, seg%centre - [2 * radius, 0.0_dp], cp, normal, dist, where)
    r = cp(1)
  end function arc_least_r

  !> bulkflow's TYPE=PLANE: point line, normal line.
  subroutine read_plane(blk, ndim, rs, err)
    type(keyword_block_t), intent(in) :: blk
    integer, intent(in) :: ndim
    type(rigid_surface_t), intent(inout) :: rs
    type(error_t), intent(inout) :: err
    real(dp) :: length
    integer :: k

    if (ndim /= 3) then
       call blk%fail('*SURFACE, TYPE=PLANE in a 2D model; expected TYPE=SEGMENTS for a 2D wall', err)
       return
    end if
    call expect_lines(blk, 2, 2, 'a point line x, y, z and a normal line nx, ny, nz', err)
    if (err%raised) return
    call expect_fields(blk, blk%lines(1), 3, 3, 'a point x, y, z', err)
    if (.not. err%raised) call expect_fields(blk, blk%lines(2), 3, 3, 'a normal nx, ny, nz', err)
    if (err%raised) return
    do k = 1, 3
       call get_real(blk%lines(1), k, rs%point(k), err)
       if (.not. err%raised) call get_real(blk%lines(2), k, rs%normal(k), err)
       if (err%raised) return
    end do
    length = norm2(rs%normal)
    if (.not. (length > 0)) then
       call raise_error(blk%lines(2)%file, blk%lines(2)%line, 'plane normal is zero; expected a ' // &
            'non-zero normal nx, ny, nz', err)
       return
    end if
    rs%normal = rs%normal / length
    allocate (rs%segments(0))
    rs%n_segments = 0
  end subroutine read_plane

  !> *RIGID BODY, REF NODE=node or one-node set, ANALYTICAL SURFACE=name.
  subroutine build_rigid_bodies(deck, layout, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: ref, surface
    logical, allocatable :: in_element(:)
    integer :: i, k, node, id, ks

    allocate (in_element(model%mesh%n_nodes))
    in_element = .false.
    do k = 1, model%mesh%n_elems
       in_element(model%mesh%conn(:, k)) = .true.
    end do
    do i = 1, deck%n_blocks
       if (layout%step_of(i) /= 0 .or. deck%blocks(i)%name /= 'RIGID BODY') cycle
       associate (blk => deck%blocks(i))
         call blk%check_params([character(len=18) :: 'REF NODE', 'ANALYTICAL SURFACE'], err)
         if (.not. err%raised) call blk%get_string('REF NODE', ref, err)
         if (.not. err%raised) call blk%get_string('ANALYTICAL SURFACE', surface, err)
         if (.not. err%raised) call expect_lines(blk, 0, 0, 'no data lines', err)
         if (err%raised) return
         node = 0
         if (is_integer_text(ref)) then
            read (ref, *) id
            node = model%mesh%node_index(id)
            if (node == 0) then
               call blk%fail('reference node ' // ref // ' is not defined; expected a node given ' // &
                    'in *NODE', err)
               return
            end if
         else
            k = find_set(model%nsets, model%n_nsets, ref)
            if (k == 0) then
               call blk%fail('node set ' // ref // ' is not defined; expected a node number or a ' // &
                    'one-node *NSET', err)
               return
            end if
            if (size(model%nsets(k)%members) /= 1) then
               call blk%fail('node set ' // ref // ' has ' // itoa(size(model%nsets(k)%members)) // &
                    ' nodes; expected exactly one reference node', err)
               return
            end if
            node = model%nsets(k)%members(1)
         end if
         if (in_element(node)) then
            call blk%fail('reference node ' // itoa(model%mesh%node_id(node)) // ' belongs to an ' // &
                 'element; expected a separate node for the rigid body', err)
            return
         end if
         ks = find_rigid_surface(model, surface)
         if (ks == 0) then
            call blk%fail('analytical surface ' // surface // ' is not defined; expected a *SURFACE ' // &
                 'of TYPE=SEGMENTS or TYPE=PLANE', err)
            return
         end if
         if (model%rigid_surfaces(ks)%ref_node /= 0) then
            call blk%fail('surface ' // surface // ' already belongs to a rigid body; expected one ' // &
                 '*RIGID BODY per analytical surface', err)
            return
         end if
         model%rigid_surfaces(ks)%ref_node = node
       end associate
    end do
  end subroutine build_rigid_bodies

  !> k = the element surface `name` of data line dl, or an error at dl: "is a rigid surface"
  !> followed by `rigid_expected` when it names a rigid surface, else "is not defined".
  subroutine require_element_surface(model, dl, name, rigid_expected, k, err)
    type(model_t), intent(in) :: model
    type(data_line_t), intent(in) :: dl
    character(len=*), intent(in) :: name, rigid_expected
    integer, intent(out) :: k
    type(error_t), intent(inout) :: err

    k = find_element_surface(model, name)
    if (k > 0) return
    if (find_rigid_surface(model, name) /= 0) then
       call raise_error(dl%file, dl%line, 'surface ' // name // ' is ' // rigid_expected, err)
    else
       call raise_error(dl%file, dl%line, 'surface ' // name // ' is not defined; expected the ' // &
            'name of a *SURFACE, TYPE=ELEMENT', err)
    end if
  end subroutine require_element_surface
end module scene_surfaces
