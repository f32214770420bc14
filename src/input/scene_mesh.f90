!> The mesh of a scene: *NODE and *ELEMENT blocks -> model%mesh (nodes and elements
!> sorted by user number, connectivity by internal index), plus the sets named by their
!> NSET=/ELSET= parameters.
!>
!> All *NODE blocks are read before any *ELEMENT is resolved, so their order in the file
!> does not matter (as in Abaqus). One continuum element type per model: CPE4R (2D plane
!> strain) or C3D8R (3D); the type fixes ndim. In 2D a node may carry a third coordinate
!> only if it is zero (files written for 3D post-processors often do that).
module scene_mesh
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t, data_line_t
  use model, only: model_t
  use model_mesh, only: element_cpe4r, element_c3d8r, element_cax4r
  use model_sets, only: name_length
  use scene_layout, only: scene_layout_t
  use scene_sets, only: add_members
  use scene_util, only: itoa, get_int, get_real, append_int, sort_permutation, &
       where_text, last_field, expect_lines, check_name
  implicit none
  private

  public :: mesh_sources_t, build_mesh
  public :: read_nodes   ! the reference nodes of an MPM scene's rigid bodies (scene_reader)

  !> Where each internal element was defined (for later messages about elements).
  type :: mesh_sources_t
     integer, allocatable :: elem_block(:), elem_line(:)
  end type mesh_sources_t

contains

  subroutine build_mesh(deck, layout, model, sources, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(model_t), intent(inout) :: model
    type(mesh_sources_t), intent(out) :: sources
    type(error_t), intent(inout) :: err

    call element_type(deck, layout, model, err)
    if (err%raised) return
    call read_nodes(deck, layout, model, err)
    if (err%raised) return
    call read_elements(deck, layout, model, sources, err)
  end subroutine build_mesh

  !> The one element type of the model, from the TYPE= of every *ELEMENT.
  subroutine element_type(deck, layout, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: etype, first_type
    integer :: i, first

    first = 0
    do i = 1, deck%n_blocks
       if (layout%step_of(i) /= 0 .or. deck%blocks(i)%name /= 'ELEMENT') cycle
       associate (blk => deck%blocks(i))
         call blk%check_params([character(len=8) :: 'TYPE', 'ELSET'], err)
         if (err%raised) return
         call blk%get_string('TYPE', etype, err)
         if (err%raised) return
         if (etype /= 'CPE4R' .and. etype /= 'C3D8R' .and. etype /= 'CAX4R') then
            call blk%fail('element type ' // etype // ' is not supported; expected TYPE=CPE4R ' // &
                 '(2D plane strain), TYPE=CAX4R (axisymmetric, x = r, y = z) or TYPE=C3D8R (3D)', err)
            return
         end if
         if (first == 0) then
            first = i
            first_type = etype
         else if (etype /= first_type) then
            call blk%fail('element type ' // etype // ' differs from ' // first_type // ' at ' // &
                 where_text(deck%blocks(first)%file, deck%blocks(first)%line) // &
                 '; expected one continuum element type per model', err)
            return
         end if
       end associate
    end do
    if (first == 0) then
       if (deck%n_blocks > 0) then
          call deck%blocks(1)%fail('the scene has no *ELEMENT; expected a mesh of CPE4R or ' // &
               'C3D8R elements', err)
       end if
       return
    end if
    if (first_type == 'CPE4R') then
       model%mesh%element_type = element_cpe4r
       model%mesh%ndim = 2
       model%mesh%nen = 4
    else if (first_type == 'CAX4R') then
       model%mesh%element_type = element_cax4r
       model%mesh%ndim = 2
       model%mesh%nen = 4
    else
       model%mesh%element_type = element_c3d8r
       model%mesh%ndim = 3
       model%mesh%nen = 8
    end if
  end subroutine element_type

  subroutine read_nodes(deck, layout, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    integer, allocatable :: ids(:), src_block(:), src_line(:), perm(:), members(:)
    real(dp), allocatable :: x(:, :), tmp(:, :)
    integer :: i, il, n, nb, ns, nl, ndim, k, id, nf, later, m
    real(dp) :: z

    ndim = model%mesh%ndim
    n = 0
    nb = 0
    ns = 0
    nl = 0
    allocate (x(3, 64))
    do i = 1, deck%n_blocks
       if (layout%step_of(i) /= 0 .or. deck%blocks(i)%name /= 'NODE') cycle
       associate (blk => deck%blocks(i))
         call blk%check_params([character(len=8) :: 'NSET'], err)
         if (err%raised) return
         call expect_lines(blk, 1, huge(1), 'node number, x, y[, z]', err)
         if (err%raised) return
         do il = 1, blk%n_lines
            associate (dl => blk%lines(il))
              nf = last_field(dl)
              if (nf < 3 .or. nf > 4) then
                 call raise_error(dl%file, dl%line, 'node line has ' // itoa(nf) // &
                      ' values; expected node number, x, y[, z]', err)
                 return
              end if
              call get_int(dl, 1, id, err)
              if (err%raised) return
              if (id < 1) then
                 call raise_error(dl%file, dl%line, 'node number ' // itoa(id) // &
                      ' is not positive; expected node numbers >= 1', err)
                 return
              end if
              if (n >= size(x, 2)) then
                 allocate (tmp(3, 2 * n))
                 tmp(:, 1:n) = x(:, 1:n)
                 call move_alloc(tmp, x)
              end if
              n = n + 1
              x(:, n) = 0
              do k = 1, 3
                 call get_real(dl, 1 + k, x(k, n), err, default=0.0_dp)
                 if (err%raised) return
              end do
              z = x(3, n)
              if (ndim == 2 .and. abs(z) > 0) then
                 call raise_error(dl%file, dl%line, 'node ' // itoa(id) // ' has z = ' // &
                      dl%field(4) // ' in a 2D (CPE4R/CAX4R) model; expected x, y (or z = 0)', err)
                 return
              end if
              call append_int(ids, nb, id)
              call append_int(src_block, ns, i)
              call append_int(src_line, nl, il)
            end associate
         end do
       end associate
    end do
    if (n == 0) then
       call deck%blocks(1)%fail('the scene has no *NODE; expected the nodes of the mesh', err)
       return
    end if
    call sort_permutation(ids(1:n), perm)
    ! a duplicate is reported at its later definition (stable sort: larger position)
    do k = 2, n
       if (ids(perm(k)) == ids(perm(k - 1))) then
          later = max(perm(k), perm(k - 1))
          m = min(perm(k), perm(k - 1))
          associate (dl => deck%blocks(src_block(later))%lines(src_line(later)), &
               first => deck%blocks(src_block(m))%lines(src_line(m)))
            call raise_error(dl%file, dl%line, 'node ' // itoa(ids(later)) // ' defined twice ' // &
                 '(first at ' // where_text(first%file, first%line) // '); expected unique node numbers', err)
          end associate
          return
       end if
    end do
    model%mesh%n_nodes = n
    allocate (model%mesh%x0(ndim, n), model%mesh%node_id(n))
    do k = 1, n
       model%mesh%node_id(k) = ids(perm(k))
       model%mesh%x0(:, k) = x(1:ndim, perm(k))
    end do
    ! NSET= of *NODE
    do i = 1, deck%n_blocks
       if (layout%step_of(i) /= 0 .or. deck%blocks(i)%name /= 'NODE') cycle
       if (.not. deck%blocks(i)%has_param('NSET')) cycle
       associate (blk => deck%blocks(i))
         call nodes_of_block(blk, model, members, err)
         if (err%raised) return
         call add_set_param(blk, 'NSET', model, .true., members, err)
         if (err%raised) return
       end associate
    end do
  end subroutine read_nodes

  subroutine nodes_of_block(blk, model, members, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    integer, allocatable, intent(out) :: members(:)
    type(error_t), intent(inout) :: err
    integer :: il, id

    allocate (members(blk%n_lines))
    do il = 1, blk%n_lines
       call get_int(blk%lines(il), 1, id, err)
       if (err%raised) return
       members(il) = model%mesh%node_index(id)
    end do
  end subroutine nodes_of_block

  !> NSET=/ELSET= parameter of *NODE or *ELEMENT: add the block's members to that set.
  subroutine add_set_param(blk, pname, model, nodal, members, err)
    type(keyword_block_t), intent(in) :: blk
    character(len=*), intent(in) :: pname
    type(model_t), intent(inout) :: model
    logical, intent(in) :: nodal
    integer, intent(in) :: members(:)
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name

    call blk%get_string(pname, name, err)
    if (.not. err%raised) call check_name(blk, 'set', name, name_length, err)
    if (err%raised) return
    if (nodal) then
       call add_members(model%nsets, model%n_nsets, name, members)
    else
       call add_members(model%elsets, model%n_elsets, name, members)
    end if
  end subroutine add_set_param

  subroutine read_elements(deck, layout, model, sources, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(model_t), intent(inout) :: model
    type(mesh_sources_t), intent(out) :: sources
    type(error_t), intent(inout) :: err
    integer, allocatable :: ids(:), src_block(:), src_line(:), perm(:), nodes(:, :), tmp(:, :)
    integer, allocatable :: members(:)
    integer :: i, il, n, nb, ns, nl, nen, k, j, id, nf, later, m, e
    character(len=8) :: tname

    nen = model%mesh%nen
    tname = merge('CPE4R', 'C3D8R', nen == 4)
    if (model%mesh%element_type == element_cax4r) tname = 'CAX4R'
    n = 0
    nb = 0
    ns = 0
    nl = 0
    allocate (nodes(nen, 64))
    do i = 1, deck%n_blocks
       if (layout%step_of(i) /= 0 .or. deck%blocks(i)%name /= 'ELEMENT') cycle
       associate (blk => deck%blocks(i))
         call expect_lines(blk, 1, huge(1), 'element number and ' // itoa(nen) // ' node numbers', err)
         if (err%raised) return
         do il = 1, blk%n_lines
            associate (dl => blk%lines(il))
              nf = last_field(dl)
              if (nf /= 1 + nen) then
                 call raise_error(dl%file, dl%line, 'element line has ' // itoa(nf - 1) // &
                      ' node numbers; ' // trim(tname) // ' expects an element number and ' // &
                      itoa(nen) // ' node numbers', err)
                 return
              end if
              call get_int(dl, 1, id, err)
              if (err%raised) return
              if (id < 1) then
                 call raise_error(dl%file, dl%line, 'element number ' // itoa(id) // &
                      ' is not positive; expected element numbers >= 1', err)
                 return
              end if
              if (n >= size(nodes, 2)) then
                 allocate (tmp(nen, 2 * n))
                 tmp(:, 1:n) = nodes(:, 1:n)
                 call move_alloc(tmp, nodes)
              end if
              n = n + 1
              do k = 1, nen
                 call get_int(dl, 1 + k, nodes(k, n), err)
                 if (err%raised) return
              end do
              call append_int(ids, nb, id)
              call append_int(src_block, ns, i)
              call append_int(src_line, nl, il)
            end associate
         end do
       end associate
    end do
    call sort_permutation(ids(1:n), perm)
    do k = 2, n
       if (ids(perm(k)) == ids(perm(k - 1))) then
          later = max(perm(k), perm(k - 1))
          m = min(perm(k), perm(k - 1))
          associate (dl => deck%blocks(src_block(later))%lines(src_line(later)), &
               first => deck%blocks(src_block(m))%lines(src_line(m)))
            call raise_error(dl%file, dl%line, 'element ' // itoa(ids(later)) // ' defined twice ' // &
                 '(first at ' // where_text(first%file, first%line) // '); expected unique element numbers', err)
          end associate
          return
       end if
    end do
    model%mesh%n_elems = n
    allocate (model%mesh%conn(nen, n), model%mesh%elem_id(n), model%mesh%elem_section(n))
    allocate (sources%elem_block(n), sources%elem_line(n))
    model%mesh%elem_section = 0
    do k = 1, n
       e = perm(k)
       model%mesh%elem_id(k) = ids(e)
       sources%elem_block(k) = src_block(e)
       sources%elem_line(k) = src_line(e)
       associate (dl => deck%blocks(src_block(e))%lines(src_line(e)))
         do j = 1, nen
            model%mesh%conn(j, k) = model%mesh%node_index(nodes(j, e))
            if (model%mesh%conn(j, k) == 0) then
               call raise_error(dl%file, dl%line, 'element ' // itoa(ids(e)) // ' uses node ' // &
                    itoa(nodes(j, e)) // ', which is not defined; expected node numbers given in *NODE', err)
               return
            end if
            if (any(nodes(1:j - 1, e) == nodes(j, e))) then
               call raise_error(dl%file, dl%line, 'element ' // itoa(ids(e)) // ' uses node ' // &
                    itoa(nodes(j, e)) // ' twice; expected ' // itoa(nen) // ' distinct nodes', err)
               return
            end if
         end do
       end associate
    end do
    ! ELSET= of *ELEMENT
    do i = 1, deck%n_blocks
       if (layout%step_of(i) /= 0 .or. deck%blocks(i)%name /= 'ELEMENT') cycle
       if (.not. deck%blocks(i)%has_param('ELSET')) cycle
       associate (blk => deck%blocks(i))
         allocate (members(blk%n_lines))
         do il = 1, blk%n_lines
            call get_int(blk%lines(il), 1, id, err)
            if (err%raised) return
            members(il) = model%mesh%elem_index(id)
         end do
         call add_set_param(blk, 'ELSET', model, .false., members, err)
         deallocate (members)
         if (err%raised) return
       end associate
    end do
  end subroutine read_elements
end module scene_mesh
